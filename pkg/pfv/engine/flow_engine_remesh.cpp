// The members of FlowEngine that remesh in the foreground and adopt a new mesh, from this step
// or from a background remesh (remesher.hpp), into the engine's state: the old pressures carried
// to the new cells, its conditions, the dV/dt reference volumes (flow_engine.hpp).
#include <chrono>
#include <optional>
#include <utility>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/solver_policy.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace pfv {

void FlowEngine::adopt_finished_remesh() {
  std::optional<Remesh> r = remesher_.take_finished();
  if (!r) return;
  // The worker could not see the old mesh: blocked cells carried over now need a new system.
  const bool carried = carry_blocked_cells(r->mesh, r->cells, centres_prev_, walls_prev_);
  adopt(std::move(r->mesh), std::move(r->linear), std::move(r->cells));
  undo_.adopted_background = undo_.open;
  if (carried) system_rebuild_requested_ = true;
  run_mesh_hook();  // conditions it sets on the new cells rebuild the system (block_cell and the like)
}

Remesh FlowEngine::mesh_without_system(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                       const BoxWalls& walls) {
  remesher_.cancel();  // a remesh in flight is superseded by this one
  Remesh r{build_pore_mesh(centres, radii, walls, settings), {}, {}};
  r.cells = flat_cells(r.mesh, settings);
  carry_blocked_cells(r.mesh, r.cells, centres, walls);
  return r;
}

void FlowEngine::remesh_now(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                            double dt) {
  Remesh r = mesh_without_system(centres, radii, walls);
  // Free the old factor first (the largest object: peak memory is then one factor, not two).
  // Should the new system fail, the step is undone without the old factor, and the next step
  // starts the remesh over.
  remesher_.request();
  adopt_and_hook(std::move(r), released_solver(), dt, true);
  remesher_.restart();  // the schedule starts again
}

void FlowEngine::run_mesh_hook() {
  if (!mesh_hook) return;
  in_hook_ = true;
  try {
    mesh_hook();
  } catch (...) {
    in_hook_ = false;
    throw;
  }
  in_hook_ = false;
}

void FlowEngine::remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls) {
  refuse_inside_hook("remesh");
  begin_undo();
  try {
    validate(settings);
    validate(bc);
    validate_snapshot(centres, radii, walls);
    // No system yet: the next step builds it, with the conditions set on the new cells meanwhile.
    adopt_and_hook(mesh_without_system(centres, radii, walls), nullptr, 0, false);
  } catch (...) {
    retract_step();
    throw;
  }
  remesher_.restart();  // the schedule starts again
}

void FlowEngine::adopt_and_hook(Remesh&& r, std::unique_ptr<PressureSolver> recycled, double dt, bool with_system) {
  const auto ordering = linear_.ordering;  // survives the release of the old factor
  if (!mesh_hook && with_system) {         // the system first: the old mesh interpolates into the new one
    r.linear =
        build_linear_system(r.mesh, bc, settings, dt, ordering.get(), std::move(recycled), {&r.cells}, solve_history_);
    adopt(std::move(r.mesh), std::move(r.linear), std::move(r.cells));
    return;
  }
  r.linear.ordering = ordering;
  adopt(std::move(r.mesh), std::move(r.linear), std::move(r.cells), false);
  run_mesh_hook();
  if (!with_system) return;
  linear_ = build_linear_system(*mesh_, bc, settings, dt, ordering.get(), std::move(recycled),
                                {&cells_, &measured_void_volume_}, solve_history_);
  ++system_builds_;
  system_rebuild_requested_ = false;
}

bool FlowEngine::carry_blocked_cells(const PoreMesh& m, CellConditions& conditions, const std::vector<Vec3>& centres,
                                     const BoxWalls& walls) const {
  // The current solver: the one a remesh keeps under solver = auto.
  const SolverKind in_use = linear_.solver ? linear_.solver->kind() : settings.solver;
  if (!has_mesh() || cells_.blocked.empty() || !settings.interpolates(in_use)) return false;
  if (centres.size() != static_cast<std::size_t>(m.mesh().n_spheres)) return false;
  bool carried = false;
  const int n = m.mesh().n_cells();
  const std::vector<double> no_radii;
  const Packing packing{centres, no_radii, walls};
  std::vector<Vec3> barycentres(n);  // inside the new cell (a power centre need not be)
  for (int k = 0; k < n; ++k) barycentres[k] = cell_barycenter(m.cells.shape[k], packing);
  const std::vector<int> located = mesh_->tri.locate_all(barycentres);
  for (int k = 0; k < n; ++k) {
    const int old = located[k];
    if (old < 0 || !cells_.is_blocked(old)) continue;
    carried |= conditions.block(k, n);
    conditions.set_pressure(k, cells_.pressure_of(old), n);
  }
  return carried;
}

bool FlowEngine::auto_keeps_multigrid() const {
  return pfv::auto_keeps_multigrid(settings, linear_, history_after(linear_, solve_history_));
}

std::unique_ptr<PressureSolver> FlowEngine::released_solver() {
  solve_history_ = history_after(linear_, solve_history_);  // before the solver goes
  return release_solver(settings, linear_, solve_history_);
}

void FlowEngine::adopt(PoreMesh&& mesh, LinearSystem&& linear, CellConditions&& conditions, bool with_system) {
  // The old pressure at the new pore centres: the state of a compressible fluid, and the warm
  // start of the iterative solvers. (The direct solve of an incompressible fluid needs neither,
  // unless asked for: interpolate_on_remesh.)
  std::vector<double> pressure(mesh.mesh().n_cells(), settings.p_zero);
  const bool interpolated =
      settings.interpolates(linear.solver ? linear.solver->kind() : settings.solver) && has_mesh();
  const auto t0 = std::chrono::steady_clock::now();
  if (interpolated) {
    const std::vector<int> located = mesh_->tri.locate_all(mesh.cells.power_centre);
    for (int c = 0; c < mesh.mesh().n_cells(); ++c)
      if (located[c] >= 0) pressure[c] = pressure_[located[c]];
  }
  const double carry_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // A cell blocked at zero pressure holds zero (a flat cell, or one carried over, keeps its pressure).
  for (int c = 0; c < mesh.mesh().n_cells(); ++c)
    if (conditions.is_blocked(c) && conditions.pressure_of(c) == CellPressure::kImposed) pressure[c] = 0;
  // A solver built elsewhere (a background remesh) learns what the current one has.
  CholeskySolver* next = linear.cholesky();
  const CholeskySolver* current = linear_.cholesky();
  if (next && current && next != current) next->carry_over(*current);
  StageTimes t = mesh.times;
  t.assembly = linear.times.assembly;
  t.analysis = linear.times.analysis;
  t.factorization = linear.times.factorization;
  t.carry_over = carry_seconds;
  remesh_times_ = t;
  solve_history_ = history_after(linear_, solve_history_);
  retire_mesh();  // aside while a step that may be undone runs, else freed here
  mesh_ = std::make_unique<PoreMesh>(std::move(mesh));
  ++mesh_id_;
  linear_ = std::move(linear);
  pressure_ = std::move(pressure);
  pressures_solved_ = interpolated;  // else pZero: no history to extrapolate from
  pressure_before_.clear();          // other cells
  cells_ = std::move(conditions);    // those of the old cells named cells by index: gone
  std::vector<double>().swap(measured_void_volume_);
  const int nc = mesh_->mesh().n_cells();
  volume_.assign(mesh_->cells.volume.begin(), mesh_->cells.volume.end());
  volume_rate_.assign(nc, 0.0);
  // Previous volumes on the new cells, so that dV/dt stays an exact backward difference.
  if (has_prev_ && centres_prev_.size() == static_cast<std::size_t>(mesh_->mesh().n_spheres))
    for (int c = 0; c < nc; ++c) volume_[c] = cell_volume(mesh_->cells.shape[c], centres_prev_, walls_prev_);
  else
    has_prev_ = false;  // bodies appeared or vanished: no backward difference this step
  ++remesh_count_;
  if (with_system) ++system_builds_;
}

}  // namespace pfv
