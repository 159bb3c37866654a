#include "pfv/engine/flow_engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "pfv/common/parallel.hpp"
#include "pfv/common/stage_timer.hpp"
#include "pfv/engine/solver_policy.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace pfv {
namespace {

constexpr double kInversionFraction = 1e-3;  // of the mean cell volume (assemble)

}  // namespace

FlowEngine::~FlowEngine() {
  if (pending_) pending_->result.wait();  // the worker reads copies only, but let it finish
}

void FlowEngine::release() {
  if (pending_) pending_->result.wait();
  pending_.reset();
  mesh_.reset();
  linear_ = LinearSystem{};
  for (auto* v :
       {&pressure_, &volume_, &volume_rate_, &rhs_, &solution_, &next_volume_, &next_pressure_, &pressure_before_})
    std::vector<double>().swap(*v);
  for (auto* v : {&force_, &next_force_, &shear_force_, &next_shear_, &centres_prev_}) std::vector<Vec3>().swap(*v);
  has_prev_ = keep_trend_ = pressures_solved_ = false;
  cells_.clear();
  std::vector<double>().swap(measured_void_volume_);
  strain_ = 0;
  steps_since_remesh_ = 0;
  remesh_requested_ = true;
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
  s.steps_since_remesh = steps_since_remesh_;
  s.strain = strain_;
  return s;
}

void FlowEngine::resume(const RunState& s, double dt) {
  release();
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
  steps_since_remesh_ = s.steps_since_remesh;
  strain_ = s.strain;
}

bool FlowEngine::remesh_due() const {
  return remesh_requested_ || !has_mesh() ||
         (settings.mesh_update_interval > 0 && steps_since_remesh_ >= settings.mesh_update_interval) ||
         (settings.def_tolerance > 0 && strain_ >= settings.def_tolerance) || mesh_->recipe.stale_for(settings);
}

bool FlowEngine::metis_used() const {
  const CholeskySolver* c = linear_.cholesky();
  return c && c->factor().metis_used();
}

const CholmodSolver& FlowEngine::cholmod() const {
  const CholeskySolver* c = linear_.cholesky();
  if (!c) throw std::logic_error("the engine has no Cholesky factor (another solver, or no system yet)");
  return c->factor();
}

double FlowEngine::refinement_contraction() const {
  const CholeskySolver* c = linear_.cholesky();
  return c ? c->refinement_contraction() : -1.0;
}

void FlowEngine::step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                      double dt) {
  const auto start = StageClock::now();
  validate_step(centres, radii, walls, dt);
  schedule_remesh(centres, radii, walls, dt);
  rebuild_stale_system(dt);
  // From here on everything writes into scratch buffers; the engine's state changes only in
  // commit(), once the step has produced finite pressures and forces.
  double strain = assemble(centres, walls, dt);
  if (inverted_cells_ > 0) {
    // Spheres moved so far since the remesh that cells turned inside out: their volumes and
    // throats mean nothing any more (fluxes of the wrong sign). Remesh at these positions,
    // whatever the schedule says.
    remesh_now(centres, radii, walls, dt);
    ++inversion_remeshes_;
    strain = assemble(centres, walls, dt);
  }
  assemble_rhs();
  solve();
  compute_forces(centres, radii, dt);
  commit(centres, walls, strain);
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
  if (has_mesh() && mesh_->recipe.stale_for(settings)) remesh_requested_ = true;
  const bool same_spheres = has_mesh() && centres.size() == static_cast<std::size_t>(mesh().n_spheres);
  if (pending_ && (!same_spheres || remesh_requested_)) {
    pending_->result.wait();  // superseded: its snapshot is out of date
    pending_.reset();
  }
  adopt_finished_remesh();
  if (!same_spheres || remesh_requested_ || (remesh_due() && !pending_)) {
    if (settings.background_remesh && same_spheres && !remesh_requested_)
      remesh_in_background(centres, radii, walls, dt);
    else
      remesh_now(centres, radii, walls, dt);
  }
}

void FlowEngine::adopt_finished_remesh() {
  if (!pending_ || pending_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
  auto future = std::move(pending_->result);
  pending_.reset();
  std::optional<Remesh> r;
  try {
    r.emplace(future.get());
  } catch (...) {
    remesh_requested_ = true;  // the next step remeshes in the foreground and says why
    throw;
  }
  // The worker could not see the old mesh: blocked cells carried over now need a new system.
  const bool carried = carry_blocked_cells(r->mesh, r->cells, centres_prev_, walls_prev_);
  adopt(std::move(r->mesh), std::move(r->linear), std::move(r->cells));
  if (carried) system_rebuild_requested_ = true;
}

void FlowEngine::remesh_in_background(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                      const BoxWalls& walls, double dt) {
  // Snapshot now, build on another thread, carry on with the current mesh meanwhile. The current
  // solver stays in use; an empty multigrid solver stands for it where kAuto keeps that choice
  // (without it the worker would pay the ordering and analysis that decided it again).
  pending_ = Pending{std::async(std::launch::async, [c = centres, r = radii, w = walls, s = settings, b = bc, dt,
                                                     o = linear_.ordering, keep = auto_keeps_multigrid()]() {
    PoreMesh m = build_pore_mesh(c, r, w, s);
    CellConditions flat = flat_cells(m, s);
    std::unique_ptr<PressureSolver> recycled = background_stand_in(keep);
    LinearSystem l = build_linear_system(m, b, s, dt, o.get(), std::move(recycled), {&flat});
    return Remesh{std::move(m), std::move(l), std::move(flat)};
  })};
  strain_ = 0;
  steps_since_remesh_ = 0;
}

FlowEngine::Remesh FlowEngine::mesh_without_system(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                                   const BoxWalls& walls) {
  if (pending_) {  // superseded by this one
    pending_->result.wait();
    pending_.reset();
  }
  Remesh r{build_pore_mesh(centres, radii, walls, settings), {}, {}};
  r.cells = flat_cells(r.mesh, settings);
  carry_blocked_cells(r.mesh, r.cells, centres, walls);
  return r;
}

void FlowEngine::restart_schedule() {
  strain_ = 0;
  steps_since_remesh_ = 0;
  remesh_requested_ = false;
}

void FlowEngine::remesh_now(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                            double dt) {
  Remesh r = mesh_without_system(centres, radii, walls);
  // Free the old factor first (the largest object: peak memory is then one factor, not two).
  // Should the new system fail, the old mesh is kept without a solver and the next step starts
  // the remesh over; the last results stay readable meanwhile.
  remesh_requested_ = true;
  const auto ordering = linear_.ordering;  // survives the release of the old factor
  r.linear = build_linear_system(r.mesh, bc, settings, dt, ordering.get(), released_solver(), {&r.cells});
  adopt(std::move(r.mesh), std::move(r.linear), std::move(r.cells));
  restart_schedule();
}

void FlowEngine::remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls) {
  validate(settings);
  validate(bc);
  validate_snapshot(centres, radii, walls);
  Remesh r = mesh_without_system(centres, radii, walls);
  // No system yet: the next step builds it, with the conditions set on the new cells meanwhile.
  r.linear.ordering = linear_.ordering;
  adopt(std::move(r.mesh), std::move(r.linear), std::move(r.cells), false);
  restart_schedule();
}

CellConditions FlowEngine::flat_cells(const PoreMesh& m, const EngineSettings& s) {
  CellConditions c;
  if (s.flat_threshold < 0) return c;
  const int n = m.mesh().n_cells();
  for (int k = 0; k < n; ++k)
    if (m.cells.volume[k] <= s.flat_threshold) c.block(k, n);
  return c;
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

bool FlowEngine::auto_keeps_multigrid() const { return pfv::auto_keeps_multigrid(settings, linear_); }

std::unique_ptr<PressureSolver> FlowEngine::released_solver() { return release_solver(settings, linear_); }

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
  mesh_ = std::make_unique<PoreMesh>(std::move(mesh));
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

void FlowEngine::rebuild_stale_system(double dt) {
  // A new viscosity applies at once: the conductances are rescaled (no new triangulation), the
  // system is then stale (its recipe records the viscosity).
  if (mesh_->viscosity() != settings.conductance.viscosity) mesh_->set_viscosity(settings.conductance.viscosity);
  if (linear_.ready() && !system_rebuild_requested_ && !linear_.recipe.stale_for(settings, bc, dt)) return;
  const auto ordering = linear_.ordering;
  linear_ = build_linear_system(*mesh_, bc, settings, dt, ordering.get(), released_solver(),
                                {&cells_, &measured_void_volume_});
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
  // harmlessly, and must not force remeshes.
  const double inside_out = -kInversionFraction * mesh_->mean_cell_volume;
  int inverted_cells = 0;
  next_volume_.resize(nc);
  volume_rate_.resize(nc);
#pragma omp parallel for schedule(static) reduction(max : max_change) reduction(+ : inverted_cells) if (nc > kMinParallelLoop)
  for (int c = 0; c < nc; ++c) {
    const CellShape& shape = mesh_->cells.shape[c];
    const double oriented = oriented_cell_volume(shape, centres, walls);
    inverted_cells += shape.orientation * oriented < inside_out;
    const double v = std::abs(oriented);
    const double dv = has_prev_ ? v - volume_[c] : 0.0;
    volume_rate_[c] = dv / dt;
    max_change = std::max(max_change, std::abs(dv) / std::max(v, mesh_->mean_cell_volume));
    next_volume_[c] = v;
  }
  inverted_cells_ = inverted_cells;
  if (settings.volume_correction != 1)
    for (int c = 0; c < nc; ++c)
      if (mesh_->cells.shape[c].n_walls == 0) volume_rate_[c] *= settings.volume_correction;
  step_times_.volumes = seconds_since(t0);
  return max_change;
}

void FlowEngine::assemble_rhs() {
  // b = -dV/dt (+ V_f/(K dt) p^n, implicit Euler on the stored fluid) + imposed fluxes + the
  // couplings to the Dirichlet cells, whose pressures are this step's boundary values.
  next_pressure_ = pressure_;  // the iterative solvers' start
  const PressureSystem& system = linear_.system;
  apply_dirichlet_values(system, bc, next_pressure_);
  for (const auto& [c, p] : linear_.profile_pressure) next_pressure_[c] = p;
  apply_pressure_field();
  const int nu = system.n_unknowns();
  rhs_.resize(nu);
  for (int u = 0; u < nu; ++u) rhs_[u] = -volume_rate_[system.unknown_cell[u]];
  if (!linear_.storage.empty())
    for (int u = 0; u < nu; ++u) rhs_[u] += linear_.storage[system.unknown_cell[u]] * pressure_[system.unknown_cell[u]];
  for (std::size_t i = 0; i < linear_.imposed_flux_cells.size(); ++i) {
    const int c = linear_.imposed_flux_cells[i];
    if (c >= 0 && system.unknown[c] >= 0) rhs_[system.unknown[c]] += bc.imposed_flux[i].value;
  }
  for (std::size_t i = 0; i < linear_.coupling_k.size(); ++i)
    rhs_[linear_.coupling_unknown[i]] += linear_.coupling_k[i] * next_pressure_[linear_.coupling_cell[i]];
}

void FlowEngine::apply_pressure_field() {
  step_times_.pressure_field = 0;
  if (!pressure_field.active()) return;
  const auto t0 = StageClock::now();
  LinearSystem& l = linear_;
  if (l.field_wall != pressure_field.wall) {
    // The wall's Dirichlet cells stay those of this system until it is rebuilt (which drops
    // this list with it): gathered once, not at every step.
    l.field_cells.clear();
    l.field_at.clear();
    const PressureSystem& s = l.system;
    for (std::size_t c = 0; c < s.source.size(); ++c)
      if (s.source[c] == pressure_field.wall) {
        l.field_cells.push_back(static_cast<int>(c));
        l.field_at.push_back(mesh_->cells.power_centre[c]);
      }
    l.field_wall = pressure_field.wall;
  }
  if (l.field_cells.empty()) return;  // not a pressure wall, or each of its cells freed or blocked
  field_values_.clear();
  pressure_field.evaluate(l.field_at, field_values_);
  if (field_values_.size() != l.field_cells.size())
    throw std::invalid_argument("the pressure field of wall " + std::to_string(pressure_field.wall) + " gave " +
                                std::to_string(field_values_.size()) + " values for " +
                                std::to_string(l.field_cells.size()) + " cells");
  for (std::size_t i = 0; i < field_values_.size(); ++i) {
    if (!std::isfinite(field_values_[i]))
      throw std::invalid_argument("the pressure field of wall " + std::to_string(pressure_field.wall) +
                                  " is not finite at " + describe(l.field_at[i]));
    next_pressure_[l.field_cells[i]] = field_values_[i];
  }
  ++field_evaluations_;
  step_times_.pressure_field = seconds_since(t0);
}

void FlowEngine::solve() {
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
    last_solve_ = solver.solve(rhs_, solution_, settings.solve_control());
    keep_trend_ = solver.wants_extrapolated_start();  // false once promoted to a double factor
    for (int u = 0; u < nu; ++u) next_pressure_[system.unknown_cell[u]] = solution_[u];
  }
  step_times_.solve = seconds_since(t0);
}

void FlowEngine::compute_forces(const std::vector<Vec3>& centres, const std::vector<double>& radii, double dt) {
  auto t0 = StageClock::now();
  mesh_->cache.apply(next_pressure_, next_force_);
  if (settings.fluid_density > 0) {
    const Vec3 weight = settings.fluid_density * (4.0 / 3.0) * std::numbers::pi * settings.gravity;
    for (std::size_t k = 0; k < radii.size(); ++k) next_force_[k] -= radii[k] * radii[k] * radii[k] * weight;
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
  if (bad_p != next_pressure_.end())
    throw std::domain_error("non-finite pore pressure in cell " + std::to_string(bad_p - next_pressure_.begin()) +
                            " (check boundary values, imposed fluxes and the time step)");
  for (std::size_t v = 0; v < next_force_.size(); ++v)
    if (!next_force_[v].allFinite()) throw std::domain_error("non-finite fluid force on vertex " + std::to_string(v));

  std::swap(volume_, next_volume_);
  // The pressures before this step start the next one's extrapolation only if they were
  // solved (or carried over) on this mesh: from pZero, 2 p - p0 would double the first solution
  // and start the second step as far off as the first.
  if (keep_trend_ && pressures_solved_)
    std::swap(pressure_before_, pressure_);  // kept for the next start; its buffer becomes scratch
  else if (!pressure_before_.empty())
    std::vector<double>().swap(pressure_before_);
  std::swap(pressure_, next_pressure_);
  pressures_solved_ = true;
  std::swap(force_, next_force_);
  std::swap(shear_force_, next_shear_);
  strain_ += strain;
  ++steps_since_remesh_;
  centres_prev_ = centres;
  walls_prev_ = walls;
  has_prev_ = true;
}
double FlowEngine::boundary_flux(int wall) const {
  // Fluid leaving through the wall: what flows into its Dirichlet cells from the rest of the
  // pore space, plus what those cells expel themselves as they shrink (a moving drained wall
  // sweeps their volume). Without deformation only the first term remains.
  const PressureSystem& s = linear_.system;
  double q = 0;
  for (std::size_t c = 0; c < s.source.size(); ++c) {
    if (s.source[c] != wall) continue;
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e)
      q += s.adj_k[e] * (pressure_[s.adj_cell[e]] - pressure_[c]);
    if (c < volume_rate_.size()) q -= volume_rate_[c];
  }
  return q;
}

double FlowEngine::imposed_flux_total() const {
  double q = 0;
  const auto& cells = linear_.imposed_flux_cells;
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (cells[i] >= 0 && linear_.system.unknown[cells[i]] >= 0) q += bc.imposed_flux[i].value;
  return q;
}

double FlowEngine::volume_rate_total() const {
  double s = 0;
  for (double r : volume_rate_) s += r;
  return s;
}

double FlowEngine::average_pressure() const {
  double pv = 0, v = 0;
  for (std::size_t c = 0; c < pressure_.size(); ++c) {
    pv += pressure_[c] * mesh_->cells.volume[c];
    v += mesh_->cells.volume[c];
  }
  return v > 0 ? pv / v : 0.0;
}

double FlowEngine::average_slice_pressure(int axis, double position) const {
  // Area average over the slice, sampled on a regular grid of the wall-bounded section.
  if (axis < 0 || axis > 2) throw std::invalid_argument("axis must be 0, 1 or 2");
  constexpr int kSamples = 40;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  double sum = 0;
  int count = 0;
  for (int i = 0; i < kSamples; ++i)
    for (int j = 0; j < kSamples; ++j) {
      Vec3 x;
      x[axis] = position;
      x[a1] = walls_prev_.coord[2 * a1] + (i + 0.5) / kSamples * walls_prev_.extent(a1);
      x[a2] = walls_prev_.coord[2 * a2] + (j + 0.5) / kSamples * walls_prev_.extent(a2);
      const int c = locate(x);
      if (c < 0) continue;
      sum += pressure_[c];
      ++count;
    }
  if (count == 0) throw std::invalid_argument("the slice lies outside the pore mesh");
  return sum / count;
}

}  // namespace pfv
