#include "pfv/engine/engine_settings.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace pfv {
namespace {

void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(what);
}

}  // namespace

void validate(const EngineSettings& s) {
  const ConductanceModel& c = s.conductance;
  require(c.viscosity > 0 && std::isfinite(c.viscosity), "viscosity must be positive and finite");
  require(c.permeability_factor > 0 && std::isfinite(c.permeability_factor),
          "permeabilityFactor must be positive (the negative 'homogeneous' variant is not supported)");
  require(s.solver == SolverKind::kGaussSeidel || s.solver == SolverKind::kConjugateGradient ||
              s.solver == SolverKind::kCholesky,
          "solver must be Gauss-Seidel, conjugate gradients or Cholesky");
  require(s.relax > 0 && s.relax < 2, "relax must be in (0, 2)");
  require(s.mixed_precision_min_entries >= 0 && std::isfinite(s.mixed_precision_min_entries),
          "mixed_precision_min_entries must be finite and >= 0");
  require(s.refinement_tolerance > 0 && s.refinement_tolerance < 1, "refinement_tolerance must be in (0, 1)");
  require(s.fluid_bulk_modulus >= 0 && std::isfinite(s.fluid_bulk_modulus), "fluidBulkModulus must be >= 0 and finite");
}

}  // namespace pfv
