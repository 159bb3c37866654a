#include "pfv/engine/flow_engine.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "pfv/common/parallel.hpp"
#include "pfv/common/stage_timer.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace pfv {
namespace {

constexpr double kInversionFraction = 1e-3;  // of the mean cell volume (assemble)
// The part of the meshed volume that may be inside out before a step remeshes out of schedule
// (assemble). Below it the step runs on, as YADE's engine does until its scheduled remesh: the
// signed volumes keep the mass balance exact (cell_volume), and the error is that of the
// conductances and force areas of the old mesh, which grows with the motion since the remesh
// whether cells flip or not, and which the user's remesh schedule bounds. A fraction of the volume
// is a property of the motion, not of the packing's size: a cell flipping somewhere in a million
// costs no remesh. Random motion of every sphere by a fifth of the spacing since the remesh turns
// about 1 % of the volume inside out (mostly slivers) and puts the forces of the old mesh about a
// quarter off those of a fresh one (doc/model.md); twice that motion is past any useful schedule.
constexpr double kInvertedVolumeForRemesh = 0.02;

}  // namespace

void FlowEngine::release() {
  refuse_inside_hook("release");
  undo_.reset();
  remesher_.reset();
  mesh_.reset();
  linear_ = LinearSystem{};
  for (auto* v :
       {&pressure_, &volume_, &volume_rate_, &rhs_, &solution_, &next_volume_, &next_pressure_, &pressure_before_})
    std::vector<double>().swap(*v);
  for (auto* v : {&force_, &next_force_, &shear_force_, &next_shear_, &centres_prev_}) std::vector<Vec3>().swap(*v);
  has_prev_ = keep_trend_ = pressures_solved_ = false;
  cells_.clear();
  std::vector<double>().swap(measured_void_volume_);
  last_solve_ = SolveStats{};
}

FlowEngine::RunState FlowEngine::run_state() const {
  if (!has_mesh()) throw std::logic_error("the engine has no mesh to save: run a step first");
  RunState s;
  s.mesh = mesh_->source;
  if (has_prev_) {
    s.previous_centres = centres_prev_;
    s.previous_walls = walls_prev_;
  }
  s.pressure = pressure_;
  s.cells = cells_;
  s.void_volume = measured_void_volume_;
  s.steps_since_remesh = remesher_.steps_since_remesh();
  s.strain = remesher_.strain();
  return s;
}

void FlowEngine::resume(const RunState& s, double dt) {
  release();  // (refuses to run inside the mesh hook)
  validate(settings);
  validate(bc);
  validate_snapshot(s.mesh.centres, s.mesh.radii, s.mesh.walls);
  has_prev_ = !s.previous_centres.empty();
  if (has_prev_) {
    validate_snapshot(s.previous_centres, s.mesh.radii, s.previous_walls);
    centres_prev_ = s.previous_centres;
    walls_prev_ = s.previous_walls;
  }
  try {
    remesh_now(s.mesh.centres, s.mesh.radii, s.mesh.walls, dt);  // dV/dt reference volumes from centres_prev_
    if (s.pressure.size() != pressure_.size())
      throw std::invalid_argument("the saved pressures (" + std::to_string(s.pressure.size()) +
                                  " cells) do not fit the rebuilt mesh (" + std::to_string(pressure_.size()) +
                                  " cells)");
    const auto fits = [&](std::size_t n) { return n == 0 || n == pressure_.size(); };
    if (!fits(s.cells.pressure.size()) || !fits(s.cells.blocked.size()) || !fits(s.void_volume.size()))
      throw std::invalid_argument("the saved cell conditions or void volumes do not fit the rebuilt mesh (" +
                                  std::to_string(pressure_.size()) + " cells)");
  } catch (...) {
    release();
    throw;
  }
  pressure_ = s.pressure;
  pressures_solved_ = true;  // saved after a step
  if (!s.cells.empty() || !s.void_volume.empty()) {
    // Flat cells are found again by the rebuild; the saved conditions hold them and the rest.
    cells_ = s.cells;
    measured_void_volume_ = s.void_volume;
    system_rebuild_requested_ = true;
  }
  remesher_.restore(s.steps_since_remesh, s.strain);
}

const CholmodSolver& FlowEngine::cholmod() const {
  const CholeskySolver* c = linear_.cholesky();
  if (!c) throw std::logic_error("the engine has no Cholesky factor (another solver, or no system yet)");
  return c->factor();
}

void FlowEngine::step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                      double dt) {
  refuse_inside_hook("step");
  const auto start = StageClock::now();
  begin_undo();
  try {
    validate_step(centres, radii, walls, dt);
    schedule_remesh(centres, radii, walls, dt);
    rebuild_stale_system(dt);
    // From here on everything writes into scratch buffers; the results change only in commit(),
    // once the step has produced finite pressures and forces.
    double strain = assemble(centres, walls, dt);
    if (inverted_volume_ > kInvertedVolumeForRemesh * meshed_volume_) {
      // Spheres moved so far since the remesh that 2 % of the volume turned inside out: the
      // throats no longer describe the pore space. Remesh at these positions, whatever the
      // schedule says. (Less runs on with signed volumes: see cell_volume.)
      remesh_now(centres, radii, walls, dt);
      ++inversion_remeshes_;
      strain = assemble(centres, walls, dt);
    }
    assemble_rhs();
    solve(dt);
    compute_forces(centres, radii, dt);
    commit(centres, walls, strain);
  } catch (...) {
    retract_step();
    throw;
  }
  step_times_.total = seconds_since(start);
}

void FlowEngine::validate_step(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                               const BoxWalls& walls, double dt) const {
  if (!(dt > 0 && std::isfinite(dt))) throw std::invalid_argument("time step must be positive and finite");
  validate(settings);
  validate(bc);
  validate_snapshot(centres, radii, walls);
}

void FlowEngine::schedule_remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                 const BoxWalls& walls, double dt) {
  // Settings the mesh depends on changed: the old mesh is wrong, remesh now.
  if (has_mesh() && mesh_->recipe.stale_for(settings)) remesher_.request();
  const bool same_spheres = has_mesh() && centres.size() == static_cast<std::size_t>(mesh().n_spheres);
  const bool now = !same_spheres || remesher_.requested();
  if (now) remesher_.cancel();  // a remesh in flight is superseded
  adopt_finished_remesh();
  if (now || (remesh_due() && !remesher_.pending())) {
    if (settings.background_remesh && !now)
      remesher_.remesh_in_background(centres, radii, walls, settings, bc, dt, linear_.ordering, auto_keeps_multigrid(),
                                     history_after(linear_, solve_history_));
    else
      remesh_now(centres, radii, walls, dt);
  }
}

void FlowEngine::rebuild_stale_system(double dt) {
  // A new viscosity applies at once: the conductances are rescaled (no new triangulation), the
  // system is then stale (its recipe records the viscosity).
  if (mesh_->viscosity() != settings.conductance.viscosity) mesh_->set_viscosity(settings.conductance.viscosity);
  if (linear_.ready() && !system_rebuild_requested_ && !linear_.recipe.stale_for(settings, bc, dt)) return;
  const auto ordering = linear_.ordering;
  LinearSystem next = build_linear_system(*mesh_, bc, settings, dt, ordering.get(), released_solver(),
                                          {&cells_, &measured_void_volume_}, solve_history_);
  retire_system();
  linear_ = std::move(next);
  ++system_builds_;
  system_rebuild_requested_ = false;
}

double FlowEngine::assemble(const std::vector<Vec3>& centres, const BoxWalls& walls, double dt) {
  const auto t0 = StageClock::now();
  const int nc = mesh().n_cells();
  // Pore strain of the step, max over cells (thesis 5.13). A near-flat cell would make any
  // motion look like a huge strain, so volumes below the mean count as the mean.
  double max_change = 0;
  // A cell counts as turned inside out once its flipped volume exceeds a small part of the mean:
  // the slivers of a dense packing (volumes far below the mean) flip under any small motion,
  // harmlessly, and must not count.
  const double inside_out = -kInversionFraction * mesh_->mean_cell_volume;
  next_volume_.resize(nc);
  next_volume_rate_.resize(nc);
  // The sums over cells by fixed chunks, added in order: the same bits on one thread or on the
  // team, whichever the measured choice runs (the inversion rule must not depend on the load).
  std::array<int, kSumChunks> inverted_in{};
  std::array<double, kSumChunks> inverted_volume_in{}, meshed_volume_in{};
  const bool team = volume_loop_.team(nc);
  const auto loop_start = StageClock::now();
#pragma omp parallel for schedule(static) reduction(max : max_change) if (team)
  for (int k = 0; k < kSumChunks; ++k) {
    const int end = chunk_begin(nc, k + 1);
    int inverted_here = 0;
    double inverted_volume_here = 0, meshed_volume_here = 0;
    for (int c = chunk_begin(nc, k); c < end; ++c) {
      const CellShape& shape = mesh_->cells.shape[c];
      const double v = cell_volume(shape, centres, walls);
      const bool inverted = v < inside_out;
      inverted_here += inverted;
      inverted_volume_here += inverted ? -v : 0.0;
      meshed_volume_here += std::abs(v);
      const double dv = has_prev_ ? v - volume_[c] : 0.0;
      next_volume_rate_[c] = dv / dt;
      max_change = std::max(max_change, std::abs(dv) / std::max(v, mesh_->mean_cell_volume));
      next_volume_[c] = v;
    }
    inverted_in[k] = inverted_here;
    inverted_volume_in[k] = inverted_volume_here;
    meshed_volume_in[k] = meshed_volume_here;
  }
  volume_loop_.done(seconds_since(loop_start));
  inverted_cells_ = 0;
  inverted_volume_ = meshed_volume_ = 0;
  for (int k = 0; k < kSumChunks; ++k) {
    inverted_cells_ += inverted_in[k];
    inverted_volume_ += inverted_volume_in[k];
    meshed_volume_ += meshed_volume_in[k];
  }
  if (settings.volume_correction != 1)
    for (int c = 0; c < nc; ++c)
      if (mesh_->cells.shape[c].n_walls == 0) next_volume_rate_[c] *= settings.volume_correction;
  step_times_.volumes = seconds_since(t0);
  return max_change;
}

void FlowEngine::assemble_rhs() {
  // The pressures of this step's Dirichlet cells (the iterative solvers' start elsewhere), then b.
  next_pressure_ = pressure_;
  const PressureSystem& system = linear_.system;
  apply_dirichlet_values(system, bc, next_pressure_);
  for (const auto& [c, p] : linear_.profile_pressure) next_pressure_[c] = p;
  step_times_.pressure_field = 0;
  if (pressure_field.active()) {
    const auto t0 = StageClock::now();
    if (apply_pressure_field(pressure_field, system, mesh_->cells.power_centre, linear_.field, field_values_,
                             next_pressure_)) {
      ++field_evaluations_;
      step_times_.pressure_field = seconds_since(t0);
    }
  }
  const RhsTerms terms{next_volume_rate_,          linear_.storage, pressure_,
                       linear_.imposed_flux_cells, bc.imposed_flux, linear_.couplings};
  pfv::assemble_rhs(system, terms, next_pressure_, rhs_);
}

void FlowEngine::solve(double dt) {
  const auto t0 = StageClock::now();
  const PressureSystem& system = linear_.system;
  const int nu = system.n_unknowns();
  last_solve_ = SolveStats{};
  keep_trend_ = false;
  if (nu > 0) {  // else every cell has an imposed pressure: nothing to solve
    PressureSolver& solver = *linear_.solver;
    // With a 32-bit factor, start from the pressures extrapolated from the last two steps: in a
    // smooth motion that halves the first correction, and with it the error bound that decides
    // whether a second pass is needed (the bound, not the guess, guarantees the accuracy).
    const bool trend = solver.wants_extrapolated_start() && pressure_before_.size() == next_pressure_.size();
    solution_.resize(nu);
    for (int u = 0; u < nu; ++u) {
      const int c = system.unknown_cell[u];
      solution_[u] = trend ? 2 * next_pressure_[c] - pressure_before_[c] : next_pressure_[c];
    }
    SolveControl control = settings.solve_control();
    control.time_step = dt;  // multigrid's start: extrapolated in time
    last_solve_ = solver.solve(rhs_, solution_, control);
    linear_.tally.add(last_solve_.cg_iterations);
    undo_.tallied_iterations = last_solve_.cg_iterations;  // taken back if the step is undone
    keep_trend_ = solver.wants_extrapolated_start();       // false once promoted to a double factor
    for (int u = 0; u < nu; ++u) next_pressure_[system.unknown_cell[u]] = solution_[u];
  }
  step_times_.solve = seconds_since(t0);
}

void FlowEngine::compute_forces(const std::vector<Vec3>& centres, const std::vector<double>& radii, double dt) {
  auto t0 = StageClock::now();
  const bool team = force_loop_.team(mesh_->cache.n_terms());
  mesh_->cache.apply(next_pressure_, next_force_, team);
  force_loop_.done(seconds_since(t0));
  if (settings.fluid_density > 0) {
    const Vec3 weight = settings.fluid_density * (4.0 / 3.0) * std::numbers::pi * settings.gravity;
    for (std::size_t k = 0; k < radii.size(); ++k) {
      const Vec3 buoyancy = radii[k] * radii[k] * radii[k] * weight;
      // Named here, where the cause is known: the settings, not a force of unknown origin below.
      if (!buoyancy.allFinite())
        throw std::domain_error("the buoyancy of sphere " + std::to_string(k) +
                                ", fluid_density x its volume x gravity, is not finite (fluid_density = " +
                                describe(settings.fluid_density) + ", gravity = " + describe(settings.gravity) + ")");
      next_force_[k] -= buoyancy;
    }
  }
  step_times_.forces = seconds_since(t0);

  if (!settings.viscous_shear && mesh_->shear) {  // switched off (or adopted from before)
    mesh_->shear.reset();
    mesh_->recipe.viscous_shear = false;
  }
  if (mesh_->shear) {
    t0 = StageClock::now();
    if (has_prev_ && centres_prev_.size() == centres.size())
      mesh_->shear->add_forces(centres, centres_prev_, dt, settings.viscosity_of_shear(), next_force_, next_shear_);
    else
      next_shear_.assign(next_force_.size(), Vec3::Zero());  // no velocities yet
    step_times_.shear_forces = seconds_since(t0);
  } else if (!shear_force_.empty() || !next_shear_.empty()) {
    std::vector<Vec3>().swap(shear_force_);
    std::vector<Vec3>().swap(next_shear_);
    step_times_.shear_forces = 0;
  }
}

void FlowEngine::commit(const std::vector<Vec3>& centres, const BoxWalls& walls, double strain) {
  // Never hand NaN or infinite forces back to the DEM.
  const auto bad_p =
      std::find_if(next_pressure_.begin(), next_pressure_.end(), [](double x) { return !std::isfinite(x); });
  if (bad_p != next_pressure_.end()) {
    const auto cell = bad_p - next_pressure_.begin();
    throw std::domain_error("non-finite pore pressure in cell " + std::to_string(cell) + " at " +
                            describe(mesh_->cells.power_centre[cell]) +
                            " (check boundary values, imposed fluxes and the time step)");
  }
  // Vertices are the spheres in input order, then the six walls: named so (the caller maps them to
  // its own ids, as for every message of the step).
  const std::size_t spheres = next_force_.size() - static_cast<std::size_t>(kWallCount);
  for (std::size_t v = 0; v < next_force_.size(); ++v)
    if (!next_force_[v].allFinite())
      throw std::domain_error("non-finite fluid force on " +
                              (v < spheres ? "sphere " + std::to_string(v) : "wall " + std::to_string(v - spheres)) +
                              " (check viscosity, fluid_density, boundary values and the time step)");

  // From here on nothing throws. Each replaced buffer stays where retract_step() finds it.
  undo_.committed = true;
  std::swap(volume_, next_volume_);
  std::swap(volume_rate_, next_volume_rate_);
  // The pressures before this step start the next one's extrapolation only if they were
  // solved (or carried over) on this mesh: from pZero, 2 p - p0 would double the first solution
  // and start the second step as far off as the first.
  undo_.trend_kept = keep_trend_ && pressures_solved_;
  if (undo_.trend_kept)
    std::swap(pressure_before_, pressure_);  // kept for the next start; its buffer becomes scratch
  else
    std::swap(pressure_before_, undo_.committed_pressure_before);  // none (freed when the step is accepted)
  std::swap(pressure_, next_pressure_);
  pressures_solved_ = true;
  std::swap(force_, next_force_);
  std::swap(shear_force_, next_shear_);
  remesher_.count_step(strain);
  std::swap(centres_prev_, undo_.centres);
  centres_prev_.assign(centres.begin(), centres.end());
  undo_.walls = walls_prev_;
  walls_prev_ = walls;
  has_prev_ = true;
}

}  // namespace pfv
