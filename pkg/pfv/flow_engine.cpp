#include "flow_engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "gauss_seidel_solver.hpp"
#include "pore_mesh.hpp"
#include "snapshot.hpp"

namespace pfv {
namespace {

using Clock = std::chrono::steady_clock;

[[noreturn]] void bad_input(const std::string& what) { throw std::invalid_argument(what); }

}  // namespace

FlowEngine::~FlowEngine() {
  if (pending_) pending_->result.wait();  // the worker reads copies only, but let it finish
}

bool FlowEngine::remesh_due() const {
  return remesh_requested_ || !has_mesh() ||
         (settings.mesh_update_interval > 0 && steps_since_remesh_ >= settings.mesh_update_interval) ||
         (settings.def_tolerance > 0 && strain_ >= settings.def_tolerance) ||
         (settings.viscous_shear && !mesh_->shear);  // switched on: the pairs come with a remesh
}

void FlowEngine::adopt(PoreMesh&& mesh, LinearSystem&& linear, int bc_version) {
  // The old pressure at the new pore centres: the state of a compressible fluid, and the warm
  // start of the iterative solvers. (The direct solve of an incompressible fluid needs neither.)
  std::vector<double> pressure(mesh.mesh().n_cells(), settings.p_zero);
  if ((settings.use_solver != 3 || settings.fluid_bulk_modulus > 0) && has_mesh())
    for (int c = 0; c < mesh.mesh().n_cells(); ++c) {
      const int old = mesh_->tri.locate(mesh.cells.power_centre[c]);
      if (old >= 0) pressure[c] = pressure_[old];
    }
  StageTimes t = mesh.times;
  t.assembly = linear.times.assembly;
  t.analysis = linear.times.analysis;
  t.factorization = linear.times.factorization;
  remesh_times_ = t;
  mesh_ = std::make_unique<PoreMesh>(std::move(mesh));
  linear_ = std::move(linear);
  linear_bc_version_ = bc_version;
  pressure_ = std::move(pressure);
  const int nc = mesh_->mesh().n_cells();
  volume_.assign(mesh_->cells.volume.begin(), mesh_->cells.volume.end());
  volume_rate_.assign(nc, 0.0);
  // Previous volumes on the new cells, so that dV/dt stays an exact backward difference.
  if (has_prev_ && centres_prev_.size() == static_cast<std::size_t>(mesh_->mesh().n_spheres))
    for (int c = 0; c < nc; ++c) volume_[c] = cell_volume(mesh_->cells.shape[c], centres_prev_, walls_prev_);
  else
    has_prev_ = false;  // bodies appeared or vanished: no backward difference this step
  ++remesh_count_;
}

void FlowEngine::step(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                      const BoxWalls& walls, double dt) {
  if (!(dt > 0 && std::isfinite(dt))) bad_input("time step must be positive and finite");
  if (!(settings.conductance.viscosity > 0 && std::isfinite(settings.conductance.viscosity)))
    bad_input("viscosity must be positive and finite");
  if (!(settings.conductance.permeability_factor > 0))
    bad_input("permeabilityFactor must be positive (the negative 'homogeneous' variant is not supported)");
  if (settings.use_solver != 0 && settings.use_solver != 1 && settings.use_solver != 3)
    bad_input("useSolver must be 0 (Gauss-Seidel), 1 (preconditioned CG) or 3 (CHOLMOD)");
  validate_snapshot(centres, radii, walls);
  if (settings.viscous_shear && has_mesh() && !mesh_->shear) remesh_requested_ = true;  // in the foreground

  const bool same_spheres = has_mesh() && centres.size() == static_cast<std::size_t>(mesh().n_spheres);
  if (pending_ && (!same_spheres || remesh_requested_)) {
    pending_->result.wait();  // superseded: its snapshot is out of date
    pending_.reset();
  }
  if (pending_ && pending_->result.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    const int version = pending_->bc_version;
    auto future = std::move(pending_->result);
    pending_.reset();
    std::optional<Remesh> r;
    try {
      r.emplace(future.get());
    } catch (...) {
      remesh_requested_ = true;  // the next step remeshes in the foreground and says why
      throw;
    }
    adopt(std::move(r->first), std::move(r->second), version);
  }
  if (!same_spheres || remesh_requested_ || (remesh_due() && !pending_)) {
    if (settings.background_remesh && same_spheres && !remesh_requested_) {
      // Snapshot now, build on another thread, carry on with the current mesh meanwhile.
      pending_ = Pending{std::async(std::launch::async,
                                    [c = centres, r = radii, w = walls, s = settings, b = bc, dt,
                                     o = linear_.ordering]() {
                                      PoreMesh m = build_pore_mesh(c, r, w, s);
                                      LinearSystem l = build_linear_system(m, b, s, dt, o.get());
                                      return Remesh(std::move(m), std::move(l));
                                    }),
                         bc_version_};
      strain_ = 0;
      steps_since_remesh_ = 0;
    } else {
      PoreMesh m = build_pore_mesh(centres, radii, walls, settings);
      // Free the old factor first (the largest object: peak memory is then one factor, not
      // two). Should the new system fail, the old mesh is kept without a factor and the next
      // step starts the remesh over; the last results stay readable meanwhile.
      remesh_requested_ = true;
      const auto ordering = linear_.ordering;  // survives the release of the old factor
      linear_.cholmod = std::make_unique<CholmodSolver>();
      linear_.pcg = PcgSolver{};
      LinearSystem l = build_linear_system(m, bc, settings, dt, ordering.get());
      adopt(std::move(m), std::move(l), bc_version_);
      strain_ = 0;
      steps_since_remesh_ = 0;
      remesh_requested_ = false;
    }
  }
  const bool solver_missing = linear_.system.n_unknowns() > 0 &&
                              ((settings.use_solver == 3 && (!linear_.cholmod->ready() ||
                                                             linear_.mixed_precision != settings.mixed_precision)) ||
                               (settings.use_solver == 1 && !linear_.pcg.ready()));
  const bool storage_stale = (settings.fluid_bulk_modulus > 0) != !linear_.storage.empty() ||
                             (!linear_.storage.empty() && dt != linear_.dt);
  if (linear_bc_version_ != bc_version_ || solver_missing || storage_stale) {
    // New boundary conditions, a solver chosen after the last remesh, or a new dt or bulk
    // modulus with a compressible fluid.
    linear_ = build_linear_system(*mesh_, bc, settings, dt, linear_.ordering.get());
    linear_bc_version_ = bc_version_;
  }

  // Everything below writes into scratch buffers; the engine's state changes only once the
  // step has produced finite pressures and forces.
  auto t0 = Clock::now();
  const int nc = mesh().n_cells();
  // Pore strain of the step, max over cells (thesis 5.13). A near-flat cell would make any
  // motion look like a huge strain, so volumes below the mean count as the mean.
  double max_change = 0;
  next_volume_.resize(nc);
  volume_rate_.resize(nc);
#pragma omp parallel for schedule(static) reduction(max : max_change) if (nc > kMinParallelLoop)
  for (int c = 0; c < nc; ++c) {
    const double v = cell_volume(mesh_->cells.shape[c], centres, walls);
    const double dv = has_prev_ ? v - volume_[c] : 0.0;
    volume_rate_[c] = dv / dt;
    max_change = std::max(max_change, std::abs(dv) / std::max(v, mesh_->mean_cell_volume));
    next_volume_[c] = v;
  }
  step_times_.volumes = seconds_since(t0);

  t0 = Clock::now();
  next_pressure_ = pressure_;  // Gauss-Seidel warm start
  const PressureSystem& system = linear_.system;
  apply_dirichlet_values(system, bc, next_pressure_);
  const int nu = system.n_unknowns();
  rhs_.resize(nu);
  for (int u = 0; u < nu; ++u) rhs_[u] = -volume_rate_[system.unknown_cell[u]];
  if (!linear_.storage.empty())  // implicit Euler on the stored fluid: + V_f/(K dt) p^n
    for (int u = 0; u < nu; ++u) rhs_[u] += linear_.storage[system.unknown_cell[u]] * pressure_[system.unknown_cell[u]];
  for (std::size_t i = 0; i < linear_.imposed_flux_cells.size(); ++i) {
    const int c = linear_.imposed_flux_cells[i];
    if (c >= 0 && system.unknown[c] >= 0) rhs_[system.unknown[c]] += bc.imposed_flux[i].value;
  }
  if (nu == 0) {
    // every cell has an imposed pressure: nothing to solve
  } else if (settings.use_solver == 0) {
    const auto r = gauss_seidel(system, rhs_, next_pressure_, settings.tolerance, settings.relax, settings.max_gs_iterations);
    gs_iterations_ = r.iterations;
  } else if (settings.use_solver == 1) {
    for (std::size_t i = 0; i < linear_.coupling_k.size(); ++i)
      rhs_[linear_.coupling_unknown[i]] += linear_.coupling_k[i] * next_pressure_[linear_.coupling_cell[i]];
    solution_.resize(nu);
    for (int u = 0; u < nu; ++u) solution_[u] = next_pressure_[system.unknown_cell[u]];  // warm start
    linear_.pcg.solve(rhs_, solution_, settings.tolerance, settings.max_gs_iterations);
    gs_iterations_ = linear_.pcg.iterations();
    for (int u = 0; u < nu; ++u) next_pressure_[system.unknown_cell[u]] = solution_[u];
  } else {
    for (std::size_t i = 0; i < linear_.coupling_k.size(); ++i)
      rhs_[linear_.coupling_unknown[i]] += linear_.coupling_k[i] * next_pressure_[linear_.coupling_cell[i]];
    if (linear_.cholmod->single_precision()) {
      solution_.resize(nu);
      for (int u = 0; u < nu; ++u) solution_[u] = next_pressure_[system.unknown_cell[u]];  // warm start
      if (!linear_.refinement.solve(system, *linear_.cholmod, rhs_, solution_, settings.refinement_tolerance,
                                    settings.max_refinement_passes)) {
        linear_.cholmod->promote_to_double(system);  // G too ill-conditioned for a float factor
        linear_.cholmod->solve(rhs_, solution_);
      }
      gs_iterations_ = linear_.refinement.passes();
    } else {
      linear_.cholmod->solve(rhs_, solution_);
    }
    for (int u = 0; u < nu; ++u) next_pressure_[system.unknown_cell[u]] = solution_[u];
  }
  step_times_.solve = seconds_since(t0);

  t0 = Clock::now();
  mesh_->cache.apply(next_pressure_, next_force_);
  step_times_.forces = seconds_since(t0);

  if (!settings.viscous_shear && mesh_->shear) mesh_->shear.reset();  // switched off (or adopted from before)
  if (mesh_->shear) {
    t0 = Clock::now();
    if (has_prev_ && centres_prev_.size() == centres.size())
      mesh_->shear->add_forces(centres, centres_prev_, dt, settings.conductance.viscosity, next_force_, next_shear_);
    else
      next_shear_.assign(next_force_.size(), Vec3::Zero());  // no velocities yet
    step_times_.shear_forces = seconds_since(t0);
  } else if (!shear_force_.empty() || !next_shear_.empty()) {
    std::vector<Vec3>().swap(shear_force_);
    std::vector<Vec3>().swap(next_shear_);
    step_times_.shear_forces = 0;
  }

  // Never hand NaN or infinite forces back to the DEM.
  const auto bad_p = std::find_if(next_pressure_.begin(), next_pressure_.end(), [](double x) { return !std::isfinite(x); });
  if (bad_p != next_pressure_.end())
    throw std::domain_error("non-finite pore pressure in cell " + std::to_string(bad_p - next_pressure_.begin()) +
                            " (check boundary values, imposed fluxes and the time step)");
  for (std::size_t v = 0; v < next_force_.size(); ++v)
    if (!next_force_[v].allFinite()) throw std::domain_error("non-finite fluid force on vertex " + std::to_string(v));

  std::swap(volume_, next_volume_);
  std::swap(pressure_, next_pressure_);
  std::swap(force_, next_force_);
  std::swap(shear_force_, next_shear_);
  strain_ += max_change;
  ++steps_since_remesh_;
  centres_prev_ = centres;
  walls_prev_ = walls;
  has_prev_ = true;
}

double FlowEngine::viscous_stability_limit(const std::vector<double>& mass, int iterations,
                                           std::vector<Vec3>* mode) const {
  if (!has_mesh() || !has_prev_) throw std::logic_error("the stability limit needs a mesh: run a step first");
  const int n = mesh().n_spheres, nc = mesh().n_cells();
  if (static_cast<int>(mass.size()) != n) bad_input("one mass per sphere is needed");
  const PressureSystem& system = linear_.system;
  const int nu = system.n_unknowns();
  const bool direct = linear_.cholmod->ready();
  if (nu == 0 || (!direct && !linear_.pcg.ready() && settings.use_solver != 0)) return HUGE_VAL;

  // Velocity probe: unit norm over the moving spheres; the given mode, else a deterministic start.
  std::vector<Vec3> v(n, Vec3::Zero()), shifted(centres_prev_);
  double norm = 0;
  if (mode && static_cast<int>(mode->size()) == n)
    for (int k = 0; k < n; ++k)
      if (mass[k] > 0 && (*mode)[k].allFinite()) {
        v[k] = (*mode)[k];
        norm += v[k].squaredNorm();
      }
  const bool warm = norm > 0;
  if (!warm)
    for (int k = 0; k < n; ++k)
      if (mass[k] > 0) {
        v[k] = Vec3(std::sin(1.0 + 3.1 * k), std::cos(2.0 + 1.7 * k), std::sin(0.5 + 2.3 * k));
        norm += v[k].squaredNorm();
      }
  if (norm == 0) return HUGE_VAL;
  double h = 0;  // probe displacement: a tiny fraction of the box
  for (int a = 0; a < 3; ++a) h = std::max(h, walls_prev_.extent(a));
  h *= 1e-7;
  std::vector<double> rhs(nu), x, p_cells(nc, 0.0), gs_p;
  std::vector<Vec3> force, shear;
  double lambda = 0;
  for (int it = 0; it < iterations; ++it) {
    norm = 0;
    for (const Vec3& u : v) norm += u.squaredNorm();
    norm = std::sqrt(norm);
    for (Vec3& u : v) u /= norm;
    // dV/dt for unit velocity v, by central differences (cell volumes are smooth in x).
    for (int u = 0; u < nu; ++u) {
      const int c = system.unknown_cell[u];
      const CellShape& shape = mesh_->cells.shape[c];
      for (int k = 0; k < 4 - shape.n_walls; ++k) shifted[shape.v[k]] = centres_prev_[shape.v[k]] + h * v[shape.v[k]];
      const double plus = cell_volume(shape, shifted, walls_prev_);
      for (int k = 0; k < 4 - shape.n_walls; ++k) shifted[shape.v[k]] = centres_prev_[shape.v[k]] - h * v[shape.v[k]];
      const double minus = cell_volume(shape, shifted, walls_prev_);
      for (int k = 0; k < 4 - shape.n_walls; ++k) shifted[shape.v[k]] = centres_prev_[shape.v[k]];
      rhs[u] = -(plus - minus) / (2 * h);
    }
    if (direct) {
      const_cast<CholmodSolver&>(*linear_.cholmod).solve(rhs, x);
    } else {  // the iterative solvers, to a tight tolerance
      gs_p.assign(nc, 0.0);
      gauss_seidel(system, rhs, gs_p, 1e-10, settings.relax, settings.max_gs_iterations);
      x.resize(nu);
      for (int u = 0; u < nu; ++u) x[u] = gs_p[system.unknown_cell[u]];
    }
    for (int u = 0; u < nu; ++u) p_cells[system.unknown_cell[u]] = x[u];
    mesh_->cache.apply(p_cells, force);
    if (mesh_->shear) mesh_->shear->add_velocity_forces(v, settings.conductance.viscosity, force, shear);
    double a_norm = 0;
    for (int k = 0; k < n; ++k) {
      v[k] = mass[k] > 0 ? Vec3(force[k] / mass[k]) : Vec3::Zero();
      a_norm += v[k].squaredNorm();
    }
    const double previous = lambda;
    lambda = std::sqrt(a_norm);  // |M^-1 V v| for |v| = 1
    if (lambda == 0) return HUGE_VAL;
    // Started from the previous mesh's mode, the estimate settles in a few iterations: stop once
    // it changes by less than 0.5 %. (A cold start can creep for many iterations while still far
    // from the answer, so it runs them all.)
    if (warm && it >= 2 && std::abs(lambda - previous) <= 5e-3 * lambda) break;
  }
  if (mode) {
    for (Vec3& u : v) u /= lambda;
    *mode = std::move(v);
  }
  return 2.0 / lambda;
}

double FlowEngine::boundary_flux(int wall) const {
  // Fluid leaving through the wall: what flows into its Dirichlet cells from the rest of the
  // pore space, plus what those cells expel themselves as they shrink (a moving drained wall
  // sweeps their volume). Without deformation only the first term remains.
  const PressureSystem& s = linear_.system;
  double q = 0;
  for (std::size_t c = 0; c < s.source.size(); ++c) {
    if (s.source[c] != wall) continue;
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) q += s.adj_k[e] * (pressure_[s.adj_cell[e]] - pressure_[c]);
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
  if (axis < 0 || axis > 2) bad_input("axis must be 0, 1 or 2");
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
  if (count == 0) bad_input("the slice lies outside the pore mesh");
  return sum / count;
}

}  // namespace pfv
