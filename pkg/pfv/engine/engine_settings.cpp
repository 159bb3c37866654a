#include "pfv/engine/engine_settings.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "pfv/engine/solver_policy.hpp"

namespace pfv {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

bool finite_positive(double x) { return x > 0 && std::isfinite(x); }

std::string named(const char* name, double value, const char* rule) {
  char got[32];
  std::snprintf(got, sizeof got, "%.6g", value);
  return std::string(name) + " must be " + rule + " (got " + got + ")";
}

}  // namespace

void validate(const EngineSettings& s) {
  const ConductanceModel& c = s.conductance;
  require(finite_positive(c.viscosity), named("viscosity", c.viscosity, "positive and finite"));
  require(finite_positive(c.permeability_factor),
          named("permeabilityFactor", c.permeability_factor,
                "positive and finite (the negative 'homogeneous' variant is not supported)"));
  require(std::isfinite(c.entrance) && c.entrance >= 0, named("conductance_entrance", c.entrance, "finite and >= 0"));
  // Checked even while clamping is off: switching it on must not reveal a bad value later.
  require(finite_positive(c.min_ratio), named("minKdivKmean", c.min_ratio, "positive and finite"));
  require(finite_positive(c.max_ratio) && c.max_ratio >= c.min_ratio,
          named("maxKdivKmean", c.max_ratio, "finite and at least minKdivKmean"));
  const std::string unavailable = solver_unavailable(s.solver);
  require(unavailable.empty(), unavailable);
  require(std::isfinite(s.shear_viscosity) && s.shear_viscosity >= 0,
          named("shear_viscosity", s.shear_viscosity, "finite and >= 0 (0: viscosity)"));
  require(std::isfinite(s.max_factor_bytes) && s.max_factor_bytes >= 0,
          named("max_factor_bytes", s.max_factor_bytes, "finite and >= 0 (0: from the memory available)"));
  // A tolerance of zero never stops Gauss-Seidel and NaN stops conjugate gradients at once.
  require(finite_positive(s.tolerance) && s.tolerance < 1, named("tolerance", s.tolerance, "in (0, 1)"));
  require(s.relax > 0 && s.relax < 2, named("relax", s.relax, "in (0, 2)"));
  require(s.max_iterations > 0, named("max_iterations", s.max_iterations, "positive"));
  require(std::isfinite(s.max_fill_growth) && s.max_fill_growth >= 1,
          named("max_fill_growth", s.max_fill_growth, "finite and at least 1"));
  require(s.mixed_precision_min_entries >= 0 && std::isfinite(s.mixed_precision_min_entries),
          named("mixed_precision_min_entries", s.mixed_precision_min_entries, "finite and >= 0"));
  require(s.refinement_tolerance > 0 && s.refinement_tolerance < 1,
          named("refinement_tolerance", s.refinement_tolerance, "in (0, 1)"));
  require(s.max_refinement_passes > 0, named("max_refinement_passes", s.max_refinement_passes, "positive"));
  require(std::isfinite(s.def_tolerance), named("defTolerance", s.def_tolerance, "finite"));
  require(std::isfinite(s.p_zero), named("pZero", s.p_zero, "finite"));
  require(s.fluid_density >= 0 && std::isfinite(s.fluid_density),
          named("fluid_density", s.fluid_density, ">= 0 and finite"));
  require(s.gravity.allFinite(), "gravity must be finite");
  require(s.fluid_bulk_modulus >= 0 && std::isfinite(s.fluid_bulk_modulus),
          named("fluidBulkModulus", s.fluid_bulk_modulus, ">= 0 and finite"));
  require(std::isfinite(s.flat_threshold), named("flatThreshold", s.flat_threshold, "finite (negative: none)"));
  require(finite_positive(s.volume_correction), named("volumeCorrection", s.volume_correction, "positive and finite"));
  require(s.minimum_porosity >= 0 && s.minimum_porosity < 1, named("minimumPorosity", s.minimum_porosity, "in [0, 1)"));
}

}  // namespace pfv
