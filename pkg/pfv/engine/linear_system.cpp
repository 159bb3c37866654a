#include "pfv/engine/linear_system.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include "pfv/common/stage_timer.hpp"
#include "pfv/linalg/amg_solver.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/gauss_seidel_solver.hpp"
#include "pfv/linalg/geometric_ordering.hpp"
#include "pfv/linalg/pcg_solver.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace pfv {
namespace {

std::vector<Vec3> positions(const std::vector<PointCondition>& conditions) {
  std::vector<Vec3> x;
  x.reserve(conditions.size());
  for (const auto& c : conditions) x.push_back(c.position);
  return x;
}

// The cell of each point; a point in no pore cell would be a condition silently dropped.
std::vector<int> locate_points(const PoreMesh& m, const std::vector<PointCondition>& conditions, const char* what) {
  std::vector<int> cells;
  cells.reserve(conditions.size());
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    const int c = m.tri.locate(conditions[i].position);
    if (c < 0)
      throw std::invalid_argument(std::string(what) + " " + std::to_string(i) + " at " +
                                  describe(conditions[i].position) +
                                  " lies in no pore cell (outside the walls or the packing)");
    cells.push_back(c);
  }
  return cells;
}

// Whether a carried-over ordering is of the kind asked for: METIS (or its nested dissection),
// AMD or the geometric dissection when one is named (forceMetis must give a METIS ordering),
// anything under kAuto and kCholmod.
bool ordering_fits(const CellOrdering& previous, Ordering wanted) {
  switch (wanted) {
    case Ordering::kMetis:
    case Ordering::kNestedDissection:
      return previous.origin() == OrderingOrigin::kMetis;
    case Ordering::kAmd:
      return previous.origin() == OrderingOrigin::kMinimumDegree;
    case Ordering::kGeometric:
      return previous.origin() == OrderingOrigin::kGeometric;
    case Ordering::kAuto:
    case Ordering::kCholmod:
      break;
  }
  return true;
}

std::unique_ptr<PressureSolver> make_solver(SolverKind kind) {
  switch (kind) {
    case SolverKind::kGaussSeidel:
      return std::make_unique<GaussSeidelSolver>();
    case SolverKind::kConjugateGradient:
      return std::make_unique<PcgSolver>();
    case SolverKind::kMultigrid:
      return std::make_unique<AmgSolver>();
    case SolverKind::kCholesky:
    case SolverKind::kAuto:
      break;
  }
  return std::make_unique<CholeskySolver>();
}

// MemAvailable of /proc/meminfo in bytes (the kernel's estimate of what can be allocated
// without swapping); 0 if unreadable.
double memory_available() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return 0;
}

// The bound on the values of a Cholesky factor: under SolverKind::kAuto, the size beyond which it
// takes multigrid (half the memory available, by default); for a named Cholesky solver, beyond
// which the factor is refused with an error (all of it: values that alone could not be stored).
double factor_entry_budget(const EngineSettings& s, const PressureSolver* recycled) {
  double bytes = s.max_factor_bytes;
  if (bytes == 0) {
    const double available = memory_available();
    if (available == 0) return std::numeric_limits<double>::infinity();  // not known: no bound
    bytes = (s.solver == SolverKind::kAuto ? 0.5 : 1.0) * available;
    if (const auto* c = dynamic_cast<const CholeskySolver*>(recycled))
      bytes += static_cast<double>(c->factor().value_capacity()) * sizeof(double);  // reused, not new
  }
  return bytes / sizeof(double);
}

// Four significant digits: a factor and the budget it is compared with may agree to three.
std::string bytes_text(double bytes) {
  char text[32];
  if (bytes >= 1e9)
    std::snprintf(text, sizeof text, "%.4g GB", bytes / 1e9);
  else
    std::snprintf(text, sizeof text, "%.4g MB", bytes / 1e6);
  return text;
}

// "the Cholesky factor would store ..., more than ...": why a factor was refused.
std::string refusal_text(const FactorTooLarge& e, const EngineSettings& s) {
  if (e.why == FactorLimit::kIndexRange) {
    char values[32];
    std::snprintf(values, sizeof values, "%.3g", e.entries);
    return std::string("the Cholesky factor would store at least ") + values +
           " values, more than the 2^31 - 1 that CHOLMOD's 32-bit indices address";
  }
  const std::string limit = s.solver == SolverKind::kAuto ? "the budget of " + bytes_text(e.limit * 8)
                            : s.max_factor_bytes > 0      ? "max_factor_bytes = " + bytes_text(e.limit * 8)
                                                          : "the " + bytes_text(e.limit * 8) + " of memory available";
  return "the Cholesky factor would store " + bytes_text(e.entries * 8) + ", more than " + limit;
}

}  // namespace

SystemRecipe::SystemRecipe(const EngineSettings& s, const BoundaryConditions& bc, double step)
    : solver(s.solver),
      viscosity(s.conductance.viscosity),
      ordering(s.factor_ordering()),
      mixed_precision(s.mixed_precision),
      mixed_precision_min_entries(s.mixed_precision_min_entries),
      max_factor_bytes(s.max_factor_bytes),
      multigrid_smoother(s.multigrid_smoother),
      fluid_bulk_modulus(s.fluid_bulk_modulus),
      minimum_porosity(s.minimum_porosity),
      dt(step),
      is_pressure(bc.is_pressure),
      imposed_pressure_at(positions(bc.imposed_pressure)),
      imposed_flux_at(positions(bc.imposed_flux)),
      profile(bc.profile) {}

bool SystemRecipe::stale_for(const EngineSettings& s, const BoundaryConditions& bc, double step) const {
  if (solver != s.solver || viscosity != s.conductance.viscosity || fluid_bulk_modulus != s.fluid_bulk_modulus ||
      is_pressure != bc.is_pressure)
    return true;
  if (fluid_bulk_modulus > 0 && (dt != step || minimum_porosity != s.minimum_porosity)) return true;
  const bool factor = solver == SolverKind::kCholesky || solver == SolverKind::kAuto;
  if (factor && (ordering != s.factor_ordering() || mixed_precision != s.mixed_precision ||
                 mixed_precision_min_entries != s.mixed_precision_min_entries))
    return true;
  if (solver == SolverKind::kAuto && max_factor_bytes != s.max_factor_bytes) return true;
  // Under kAuto also while it keeps the factor: the recipe does not know the choice.
  if ((solver == SolverKind::kMultigrid || solver == SolverKind::kAuto) && multigrid_smoother != s.multigrid_smoother)
    return true;
  if (imposed_pressure_at.size() != bc.imposed_pressure.size() || imposed_flux_at.size() != bc.imposed_flux.size() ||
      !(profile == bc.profile))
    return true;
  for (std::size_t i = 0; i < imposed_pressure_at.size(); ++i)
    if (imposed_pressure_at[i] != bc.imposed_pressure[i].position) return true;
  for (std::size_t i = 0; i < imposed_flux_at.size(); ++i)
    if (imposed_flux_at[i] != bc.imposed_flux[i].position) return true;
  return false;
}

const CholeskySolver* LinearSystem::cholesky() const { return dynamic_cast<const CholeskySolver*>(solver.get()); }
CholeskySolver* LinearSystem::cholesky() { return dynamic_cast<CholeskySolver*>(solver.get()); }

LinearSystem build_linear_system(const PoreMesh& m, const BoundaryConditions& bc, const EngineSettings& settings,
                                 double dt, const CellOrdering* previous, std::unique_ptr<PressureSolver> recycled,
                                 CellState cells) {
  LinearSystem l;
  l.recipe = SystemRecipe(settings, bc, dt);
  // Under kAuto a multigrid solver carried over keeps the choice made for the earlier mesh of
  // this engine (of a like size): every analysis that would only confirm it costs an ordering.
  const bool automatic = settings.solver == SolverKind::kAuto;
  const bool keep =
      recycled && (recycled->kind() == settings.solver || (automatic && (recycled->kind() == SolverKind::kCholesky ||
                                                                         recycled->kind() == SolverKind::kMultigrid)));
  const bool factor = automatic || settings.solver == SolverKind::kCholesky;
  const double budget = factor ? factor_entry_budget(settings, recycled.get()) : 0;
  l.solver = keep ? std::move(recycled) : make_solver(settings.solver);
  if (settings.fluid_bulk_modulus > 0) {
    const int nc = m.mesh().n_cells();
    const bool measured = cells.void_volume && static_cast<int>(cells.void_volume->size()) == nc;
    l.storage.resize(nc);
    for (int c = 0; c < nc; ++c) {
      const double v = measured ? (*cells.void_volume)[c]
                                : void_volume(m.cells.volume[c], m.cells.fluid_volume[c], settings.minimum_porosity);
      l.storage[c] = v / (settings.fluid_bulk_modulus * dt);
    }
  }
  l.imposed_pressure_cells = locate_points(m, bc.imposed_pressure, "imposed pressure");
  l.imposed_flux_cells = locate_points(m, bc.imposed_flux, "imposed flux");

  auto t0 = StageClock::now();
  static const CellConditions kNone;
  l.system = assemble_pressure_system(m.mesh(), m.facets, m.k, bc, l.imposed_pressure_cells, l.storage,
                                      cells.conditions ? *cells.conditions : kNone);
  const PressureSystem& s = l.system;
  if (!bc.profile.empty())
    for (int c = 0; c < m.mesh().n_cells(); ++c)
      if (s.source[c].is_wall(bc.profile.wall)) {
        // Beyond the profile's points the wall's value applies, read at every step as usual.
        const double x = m.cells.power_centre[c][bc.profile.axis];
        const double p = profile_pressure(bc.profile, x, std::numeric_limits<double>::quiet_NaN());
        if (!std::isnan(p)) l.profile_pressure.emplace_back(c, p);
      }
  l.couplings = dirichlet_couplings(s);
  l.times.assembly = seconds_since(t0);

  t0 = StageClock::now();
  if (s.n_unknowns() > 0) {
    if (CholeskySolver* cholesky = l.cholesky()) {
      FactorOptions options;
      options.ordering = settings.factor_ordering();
      options.precision = settings.mixed_precision ? FactorPrecision::kScaled32 : FactorPrecision::kDouble;
      options.min_scaled_entries = settings.mixed_precision_min_entries;
      options.openmp_teams = settings.cholmod_openmp_teams;
      if (previous && settings.reuse_ordering && ordering_fits(*previous, options.ordering)) {
        options.given.perm = previous->carry_over(m.mesh(), s);
        options.given.max_fill = settings.max_fill_growth * previous->fresh_fill();
        options.given.origin = previous->origin();
      }
      if (options.ordering == Ordering::kGeometric || options.ordering == Ordering::kAuto)
        options.given.geometric = [&s, &m] {
          std::vector<std::array<double, 3>> point(s.n_unknowns());
          for (int u = 0; u < s.n_unknowns(); ++u) {
            const Vec3& c = m.cells.power_centre[s.unknown_cell[u]];
            point[u] = {c[0], c[1], c[2]};
          }
          return geometric_ordering(s, point);
        };
      options.max_entries = budget;
      try {
        cholesky->setup(s, options);
        if (automatic)
          l.choice = "cholesky: the factor stores " + bytes_text(cholesky->factor().factor_nonzeros() * 8) +
                     ", within the budget of " + bytes_text(budget * 8);
      } catch (const FactorTooLarge& e) {
        if (!automatic)
          throw std::runtime_error("solver='cholesky': " + refusal_text(e, settings) +
                                   "; use solver='multigrid' (or 'auto', which takes it when the factor does not fit)");
        l.choice = "multigrid: " + refusal_text(e, settings);
        l.solver = std::make_unique<AmgSolver>();
        l.times.analysis = seconds_since(t0);
      }
    }
    if (CholeskySolver* cholesky = l.cholesky()) {
      const CholmodSolver& f = cholesky->factor();
      // The refinement's residual reads G by rows; a double factor never does.
      if (f.reduced_precision()) index_rows(l.system);
      if (f.ready() && f.permutation())
        l.ordering =
            std::make_shared<const CellOrdering>(m.mesh(), s, f.permutation(), f.chains(),
                                                 f.ordering_given() ? previous->fresh_fill() : f.fill(), f.origin());
      l.times.analysis = f.analysis_seconds();
    } else if (auto* pcg = dynamic_cast<PcgSolver*>(l.solver.get())) {
      pcg->setup(s);
    } else if (auto* amg = dynamic_cast<AmgSolver*>(l.solver.get())) {
      if (automatic && l.choice.empty()) l.choice = "multigrid: kept from the previous mesh";
      AmgParameters parameters;
      if (settings.multigrid_smoother == MultigridSmoother::kJacobi) parameters.relax_type = 18;
      if (settings.multigrid_smoother == MultigridSmoother::kSplitGaussSeidel) {
        parameters.relax_down = 13;  // l1-scaled Gauss-Seidel, forwards
        parameters.relax_up = 14;    // and backwards: the adjoint, so the cycle stays symmetric
      }
      amg->setup(s, parameters);
    }
  }
  l.times.factorization = seconds_since(t0) - l.times.analysis;
  if (l.choice.empty()) l.choice = std::string(to_string(l.solver->kind())) + ": as set";
  return l;
}

}  // namespace pfv
