#include "flow_engine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "gauss_seidel_solver.hpp"

namespace pfv {
namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

[[noreturn]] void bad_input(const std::string& what) { throw std::invalid_argument(what); }

std::string describe(const Vec3& x) {
  std::ostringstream s;
  s << "(" << x.x() << ", " << x.y() << ", " << x.z() << ")";
  return s.str();
}

}  // namespace

void validate_snapshot(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                       const BoxWalls& walls) {
  if (centres.size() != radii.size()) bad_input("positions and radii differ in length");
  if (centres.empty()) bad_input("no spheres to couple with the fluid");
  for (int w = 0; w < kWallCount; ++w)
    if (!std::isfinite(walls.coord[w])) bad_input("wall " + std::to_string(w) + " position is not finite");
  for (int a = 0; a < 3; ++a)
    if (!(walls.extent(a) > 0))
      bad_input("walls " + std::to_string(2 * a) + " and " + std::to_string(2 * a + 1) +
                " are not in increasing order (min wall at or beyond max wall)");
  for (std::size_t k = 0; k < centres.size(); ++k) {
    if (!centres[k].allFinite()) bad_input("sphere " + std::to_string(k) + " has a non-finite position " + describe(centres[k]));
    if (!(std::isfinite(radii[k]) && radii[k] > 0)) bad_input("sphere " + std::to_string(k) + " has a non-positive or non-finite radius");
    for (int w = 0; w < kWallCount; ++w)
      if (!(walls.height(w, centres[k]) > 0))
        bad_input("sphere " + std::to_string(k) + " centre " + describe(centres[k]) + " is outside wall " +
                  std::to_string(w) + " (at " + std::to_string(walls.coord[w]) + ")");
  }
}

bool FlowEngine::remesh_due() const {
  return remesh_requested_ || !has_mesh() ||
         (settings.mesh_update_interval > 0 && steps_since_remesh_ >= settings.mesh_update_interval) ||
         (settings.def_tolerance > 0 && strain_ >= settings.def_tolerance);
}

void FlowEngine::remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                        const BoxWalls& walls) {
  // Coincident centres make the triangulation drop a sphere silently: refuse them.
  std::vector<int> order(centres.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) {
    return std::lexicographical_compare(centres[a].data(), centres[a].data() + 3, centres[b].data(), centres[b].data() + 3);
  });
  for (std::size_t i = 1; i < order.size(); ++i)
    if (centres[order[i]] == centres[order[i - 1]])
      bad_input("sphere " + std::to_string(order[i - 1]) + " and sphere " + std::to_string(order[i]) +
                " have coincident centres " + describe(centres[order[i]]));

  StageTimes t;
  auto t0 = Clock::now();
  RegularTriangulation tri;
  const Mesh& mesh = tri.build(centres, radii, walls);
  const auto inside = tri.centres_inside_neighbours(centres, radii);
  if (!inside.empty())
    bad_input("sphere " + std::to_string(inside[0].first) + " and sphere " + std::to_string(inside[0].second) +
              " overlap so much that one centre lies inside the other sphere (" +
              std::to_string(inside.size()) + " such pairs); the pore mesh would be degenerate");
  if (mesh.n_cells() == 0) bad_input("the triangulation has no pore cell");
  t.triangulation = seconds_since(t0);

  t0 = Clock::now();
  const Packing packing{centres, radii, walls};
  CellGeometry cells = compute_cell_geometry(mesh, packing);
  FacetGeometry facets = compute_facet_geometry(mesh, cells, packing, settings.slip_boundary);
  t.geometry = seconds_since(t0);

  t0 = Clock::now();
  std::vector<double> k = throat_conductances(facets, settings.conductance);
  t.conductance = seconds_since(t0);

  t0 = Clock::now();
  ForceCache cache;
  cache.build(mesh, facets, packing);
  t.force_cache = seconds_since(t0);

  // Warm start for Gauss-Seidel: the old pressure at the new pore centres.
  std::vector<double> pressure(mesh.n_cells(), settings.p_zero);
  if (settings.use_solver == 0 && has_mesh())
    for (int c = 0; c < mesh.n_cells(); ++c) {
      const int old = tri_.locate(cells.power_centre[c]);
      if (old >= 0) pressure[c] = pressure_[old];
    }

  // Everything that can fail is done; commit (the system is rebuilt below from these).
  RegularTriangulation old_tri = std::move(tri_);
  tri_ = std::move(tri);
  std::swap(cells_, cells);
  std::swap(facets_, facets);
  std::swap(k_, k);
  try {
    rebuild_system();
  } catch (...) {
    tri_ = std::move(old_tri);
    std::swap(cells_, cells);
    std::swap(facets_, facets);
    std::swap(k_, k);
    throw;
  }
  cache_ = std::move(cache);
  pressure_ = std::move(pressure);
  volume_.assign(cells_.volume.begin(), cells_.volume.end());
  mean_cell_volume_ = std::accumulate(volume_.begin(), volume_.end(), 0.0) / std::max<std::size_t>(1, volume_.size());
  volume_rate_.assign(mesh.n_cells(), 0.0);
  t.assembly = remesh_times_.assembly;
  t.analysis = remesh_times_.analysis;
  t.factorization = remesh_times_.factorization;
  remesh_times_ = t;
  strain_ = 0;
  steps_since_remesh_ = 0;
  remesh_requested_ = false;
  ++remesh_count_;
}

void FlowEngine::rebuild_system() {
  const Mesh& mesh = tri_.mesh();
  std::vector<int> imposed_p(bc.imposed_pressure.size()), imposed_q(bc.imposed_flux.size());
  for (std::size_t i = 0; i < imposed_p.size(); ++i) imposed_p[i] = tri_.locate(bc.imposed_pressure[i].position);
  for (std::size_t i = 0; i < imposed_q.size(); ++i) imposed_q[i] = tri_.locate(bc.imposed_flux[i].position);

  auto t0 = Clock::now();
  PressureSystem system = assemble_pressure_system(mesh, facets_, k_, bc, imposed_p);
  std::vector<std::array<double, 2>> coupling;
  std::vector<int> coupling_cell;
  for (int u = 0; u < system.n_unknowns(); ++u) {
    const int c = system.unknown_cell[u];
    for (int e = system.adj_start[c]; e < system.adj_start[c + 1]; ++e)
      if (system.unknown[system.adj_cell[e]] < 0) {
        coupling.push_back({static_cast<double>(u), system.adj_k[e]});
        coupling_cell.push_back(system.adj_cell[e]);
      }
  }
  remesh_times_.assembly = seconds_since(t0);

  t0 = Clock::now();
  auto solver = std::make_unique<CholmodSolver>();
  if (settings.use_solver != 0)
    solver->factorize(system, settings.force_metis ? Ordering::kMetis : settings.ordering);
  remesh_times_.analysis = solver->analysis_seconds();
  remesh_times_.factorization = seconds_since(t0) - remesh_times_.analysis;

  system_ = std::move(system);
  dirichlet_coupling_ = std::move(coupling);
  dirichlet_coupling_cell_ = std::move(coupling_cell);
  cholmod_ = std::move(solver);
  imposed_pressure_cells_ = std::move(imposed_p);
  imposed_flux_cells_ = std::move(imposed_q);
  bc_dirty_ = false;
}

void FlowEngine::step(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                      const BoxWalls& walls, double dt) {
  if (!(dt > 0 && std::isfinite(dt))) bad_input("time step must be positive and finite");
  if (!(settings.conductance.viscosity > 0 && std::isfinite(settings.conductance.viscosity)))
    bad_input("viscosity must be positive and finite");
  if (!(settings.conductance.permeability_factor > 0))
    bad_input("permeabilityFactor must be positive (the negative 'homogeneous' variant is not supported)");
  if (settings.use_solver != 0 && settings.use_solver != 3)
    bad_input("useSolver must be 0 (Gauss-Seidel) or 3 (CHOLMOD)");
  validate_snapshot(centres, radii, walls);

  const bool same_spheres = has_mesh() && centres.size() == static_cast<std::size_t>(mesh().n_spheres);
  if (remesh_due() || !same_spheres) {
    remesh(centres, radii, walls);
    has_prev_ = has_prev_ && same_spheres;  // bodies appeared or vanished: no backward difference
    if (has_prev_) {  // previous volumes on the new topology, for an exact backward difference
      for (int c = 0; c < mesh().n_cells(); ++c) volume_[c] = cell_volume(cells_.shape[c], centres_prev_, walls_prev_);
    }
  } else if (bc_dirty_ || (settings.use_solver != 0 && system_.n_unknowns() > 0 && !cholmod_->ready())) {
    rebuild_system();  // new boundary conditions, or switched from Gauss-Seidel to CHOLMOD
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
    const double v = cell_volume(cells_.shape[c], centres, walls);
    const double dv = has_prev_ ? v - volume_[c] : 0.0;
    volume_rate_[c] = dv / dt;
    max_change = std::max(max_change, std::abs(dv) / std::max(v, mean_cell_volume_));
    next_volume_[c] = v;
  }
  step_times_.volumes = seconds_since(t0);

  t0 = Clock::now();
  next_pressure_ = pressure_;  // Gauss-Seidel warm start
  apply_dirichlet_values(system_, bc, next_pressure_);
  const int nu = system_.n_unknowns();
  rhs_.resize(nu);
  for (int u = 0; u < nu; ++u) rhs_[u] = -volume_rate_[system_.unknown_cell[u]];
  for (std::size_t i = 0; i < imposed_flux_cells_.size(); ++i) {
    const int c = imposed_flux_cells_[i];
    if (c >= 0 && system_.unknown[c] >= 0) rhs_[system_.unknown[c]] += bc.imposed_flux[i].value;
  }
  if (nu == 0) {
    // every cell has an imposed pressure: nothing to solve
  } else if (settings.use_solver == 0) {
    const auto r = gauss_seidel(system_, rhs_, next_pressure_, settings.tolerance, settings.relax, settings.max_gs_iterations);
    gs_iterations_ = r.iterations;
  } else {
    for (std::size_t i = 0; i < dirichlet_coupling_.size(); ++i)
      rhs_[static_cast<int>(dirichlet_coupling_[i][0])] += dirichlet_coupling_[i][1] * next_pressure_[dirichlet_coupling_cell_[i]];
    cholmod_->solve(rhs_, solution_);
    for (int u = 0; u < nu; ++u) next_pressure_[system_.unknown_cell[u]] = solution_[u];
  }
  step_times_.solve = seconds_since(t0);

  t0 = Clock::now();
  cache_.apply(next_pressure_, next_force_);
  step_times_.forces = seconds_since(t0);

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
  strain_ += max_change;
  ++steps_since_remesh_;
  centres_prev_ = centres;
  walls_prev_ = walls;
  has_prev_ = true;
}

double FlowEngine::boundary_flux(int wall) const {
  double q = 0;
  for (std::size_t c = 0; c < system_.source.size(); ++c) {
    if (system_.source[c] != wall) continue;
    for (int e = system_.adj_start[c]; e < system_.adj_start[c + 1]; ++e)
      q += system_.adj_k[e] * (pressure_[system_.adj_cell[e]] - pressure_[c]);
  }
  return q;
}

double FlowEngine::imposed_flux_total() const {
  double q = 0;
  for (std::size_t i = 0; i < imposed_flux_cells_.size(); ++i)
    if (imposed_flux_cells_[i] >= 0 && system_.unknown[imposed_flux_cells_[i]] >= 0) q += bc.imposed_flux[i].value;
  return q;
}

double FlowEngine::volume_rate_total() const {
  double s = 0;
  for (int c : system_.unknown_cell) s += volume_rate_[c];
  return s;
}

double FlowEngine::average_pressure() const {
  double pv = 0, v = 0;
  for (std::size_t c = 0; c < pressure_.size(); ++c) {
    pv += pressure_[c] * cells_.volume[c];
    v += cells_.volume[c];
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
      const int c = tri_.locate(x);
      if (c < 0) continue;
      sum += pressure_[c];
      ++count;
    }
  if (count == 0) bad_input("the slice lies outside the pore mesh");
  return sum / count;
}

}  // namespace pfv
