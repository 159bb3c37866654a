#include "pfv/engine/linear_system.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "pfv/common/stage_timer.hpp"
#include "pfv/engine/solver_policy.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/geometric_ordering.hpp"
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

// What the reuse of an ordering reads of the mesh and of the unknowns (views of both).
CellGraph cell_graph(const PoreMesh& m, const PressureSystem& s) {
  return {m.mesh().n_spheres, m.mesh().cell_vertices, m.mesh().cell_neighbours, s.unknown_cell};
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
  if (reads_multigrid_smoother(solver) && multigrid_smoother != s.multigrid_smoother) return true;
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
                                 CellState cells, const SolveHistory& history) {
  LinearSystem l;
  l.recipe = SystemRecipe(settings, bc, dt);
  SolverPlan plan = plan_solver(settings, std::move(recycled), history);
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
    SolverOptions options = solver_options(settings, plan);
    if (plan.solver->kind() == SolverKind::kCholesky) {
      if (previous && settings.reuse_ordering && ordering_fits(*previous, options.factor.ordering)) {
        options.factor.given.perm = previous->carry_over(cell_graph(m, s));
        options.factor.given.max_fill = settings.max_fill_growth * previous->fresh_fill();
        options.factor.given.origin = previous->origin();
      }
      if (options.factor.ordering == Ordering::kGeometric || options.factor.ordering == Ordering::kAuto)
        options.factor.given.geometric = [&s, &m] {
          std::vector<std::array<double, 3>> point(s.n_unknowns());
          for (int u = 0; u < s.n_unknowns(); ++u) {
            const Vec3& c = m.cells.power_centre[s.unknown_cell[u]];
            point[u] = {c[0], c[1], c[2]};
          }
          return geometric_ordering(*s.matrix, point);
        };
    }
    l.solver = set_up_solver(std::move(plan), s.matrix, options, settings, t0, l.decision);
    l.times.analysis = l.decision.analysis;
    if (const CholeskySolver* cholesky = l.cholesky()) {
      const CholmodSolver& f = cholesky->factor();
      if (f.ready() && f.permutation())
        l.ordering =
            std::make_shared<const CellOrdering>(cell_graph(m, s), f.permutation(), f.chains(),
                                                 f.ordering_given() ? previous->fresh_fill() : f.fill(), f.origin());
      l.times.analysis = f.analysis_seconds();
    }
  } else {
    l.solver = std::move(plan.solver);
  }
  l.times.factorization = seconds_since(t0) - l.times.analysis;
  if (l.decision.choice.empty()) l.decision.choice = std::string(to_string(l.solver->kind())) + ": as set";
  return l;
}

SolveHistory history_after(const LinearSystem& system, SolveHistory before) {
  const bool multigrid = system.solver && system.solver->kind() == SolverKind::kMultigrid;
  SolveHistory h = system.tally.history(before, multigrid);
  if (system.recipe.solver == SolverKind::kAuto && system.solver) {
    h.factor_values = system.decision.factor_values;
    h.multigrid_by_cost = system.decision.by_cost;
  }
  return h;
}

}  // namespace pfv
