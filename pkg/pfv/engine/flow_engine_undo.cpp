// The members of FlowEngine that make a step all or nothing (flow_engine.hpp): what a step
// replaces is moved aside, not copied, and put back when the step throws or its caller retracts
// it. A step that keeps its mesh replaces nothing large: its commit swaps buffers, and undoing it
// swaps them back. The mesh a remesh replaced lives on until the step is accepted or the next one
// begins; its factor, the largest object, is freed at once (a retracted step factorises again).
#include <stdexcept>
#include <string>
#include <utility>

#include "pfv/engine/flow_engine.hpp"

namespace pfv {

void FlowEngine::Undo::reset() {
  std::vector<Vec3> keep;
  keep.swap(centres);
  keep.clear();
  *this = Undo{};
  centres.swap(keep);
}

void FlowEngine::refuse_inside_hook(const char* what) const {
  if (in_hook_)
    throw std::logic_error(std::string(what) +
                           " called from the mesh hook (blockHook), inside a step: set "
                           "conditions on cells there, nothing else");
}

void FlowEngine::begin_undo() {
  undo_.reset();
  Undo& u = undo_;
  u.open = true;
  u.history = solve_history_;
  u.last_solve = last_solve_;
  u.schedule = remesher_.schedule();
  u.launches = remesher_.launches();
  u.has_prev = has_prev_;
  u.pressures_solved = pressures_solved_;
  u.keep_trend = keep_trend_;
  u.rebuild_requested = system_rebuild_requested_;
  u.remesh_count = remesh_count_;
  u.inversion_remeshes = inversion_remeshes_;
  u.system_builds = system_builds_;
  u.field_evaluations = field_evaluations_;
  u.inverted_cells = inverted_cells_;
  u.inverted_volume = inverted_volume_;
  u.meshed_volume = meshed_volume_;
}

void FlowEngine::retire_system() {
  if (!undo_.open || undo_.system_replaced) return;  // a system the step built itself: dropped
  undo_.system_replaced = true;
  undo_.linear = std::move(linear_);
  undo_.linear.solver.reset();  // never two factors at once: a retracted step factorises again
}

void FlowEngine::retire_mesh() {
  retire_system();
  if (!undo_.open || undo_.mesh_replaced) return;
  Undo& u = undo_;
  u.mesh_replaced = true;
  u.mesh = std::move(mesh_);
  u.cells = std::move(cells_);
  u.pressure = std::move(pressure_);
  u.pressure_before = std::move(pressure_before_);
  u.volume = std::move(volume_);
  u.volume_rate = std::move(volume_rate_);
  u.measured_void_volume = std::move(measured_void_volume_);
}

bool FlowEngine::retract_step() {
  refuse_inside_hook("retract_step");
  Undo& u = undo_;
  if (!u.open) return false;
  if (u.committed) {     // commit() in reverse
    if (u.trend_kept) {  // it rotated before <- pressure <- next
      std::swap(pressure_, pressure_before_);
      std::swap(pressure_before_, next_pressure_);
    } else {
      std::swap(pressure_, next_pressure_);
      pressure_before_ = std::move(u.committed_pressure_before);
    }
    std::swap(volume_, next_volume_);
    std::swap(volume_rate_, next_volume_rate_);
    std::swap(force_, next_force_);
    std::swap(shear_force_, next_shear_);
    std::swap(centres_prev_, u.centres);
    walls_prev_ = u.walls;
  }
  if (u.mesh_replaced) {
    mesh_ = std::move(u.mesh);
    cells_ = std::move(u.cells);
    pressure_ = std::move(u.pressure);
    pressure_before_ = std::move(u.pressure_before);
    volume_ = std::move(u.volume);
    volume_rate_ = std::move(u.volume_rate);
    measured_void_volume_ = std::move(u.measured_void_volume);
  }
  if (u.system_replaced)
    linear_ = std::move(u.linear);  // without its factor: the next step builds it again
  else if (u.tallied_iterations >= 0)
    linear_.tally.remove(u.tallied_iterations);
  solve_history_ = u.history;
  last_solve_ = u.last_solve;
  // A background remesh the step started took its inputs (settings, conditions, positions) as
  // they were at the failure: it would bring the failure back when adopted.
  if (remesher_.launches() != u.launches && remesher_.pending()) remesher_.cancel();
  // A remesh that failed asked for the next step to remesh in the foreground (and say why): that
  // stands. A background mesh the step had adopted is gone with it: the next step remeshes in the
  // foreground (the schedule restarted when that remesh began).
  Remesher::Schedule schedule = u.schedule;
  schedule.requested = schedule.requested || remesher_.requested() || u.adopted_background;
  remesher_.set_schedule(schedule);
  has_prev_ = u.has_prev;
  pressures_solved_ = u.pressures_solved;
  keep_trend_ = u.keep_trend;
  system_rebuild_requested_ = u.rebuild_requested;
  remesh_count_ = u.remesh_count;
  inversion_remeshes_ = u.inversion_remeshes;
  system_builds_ = u.system_builds;
  field_evaluations_ = u.field_evaluations;
  inverted_cells_ = u.inverted_cells;
  inverted_volume_ = u.inverted_volume;
  meshed_volume_ = u.meshed_volume;
  u.reset();
  return true;
}

void FlowEngine::accept_step() { undo_.reset(); }

}  // namespace pfv
