#include "pore_mesh.hpp"

#include "snapshot.hpp"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <stdexcept>

namespace pfv {
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

PoreMesh build_pore_mesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                         const BoxWalls& walls, const EngineSettings& settings) {
  check_distinct_centres(centres);

  PoreMesh m;
  auto t0 = Clock::now();
  const Mesh& mesh = m.tri.build(centres, radii, walls);
  const auto inside = m.tri.centres_inside_neighbours(centres, radii);
  if (!inside.empty())
    throw std::invalid_argument("sphere " + std::to_string(inside[0].first) + " and sphere " +
                                std::to_string(inside[0].second) +
                                " overlap so much that one centre lies inside the other sphere (" +
                                std::to_string(inside.size()) + " such pairs); the pore mesh would be degenerate");
  if (mesh.n_cells() == 0) throw std::invalid_argument("the triangulation has no pore cell");
  m.times.triangulation = seconds_since(t0);

  t0 = Clock::now();
  const Packing packing{centres, radii, walls};
  m.cells = compute_cell_geometry(mesh, packing);
  m.facets = compute_facet_geometry(mesh, m.cells, packing, settings.slip_boundary);
  m.mean_cell_volume = std::accumulate(m.cells.volume.begin(), m.cells.volume.end(), 0.0) / mesh.n_cells();
  m.times.geometry = seconds_since(t0);

  t0 = Clock::now();
  m.k = throat_conductances(m.facets, settings.conductance);
  m.times.conductance = seconds_since(t0);

  t0 = Clock::now();
  m.cache.build(mesh, m.facets, packing);
  m.times.force_cache = seconds_since(t0);

  if (settings.viscous_shear) {
    t0 = Clock::now();
    m.shear = build_viscous_shear(mesh, m.cells, m.facets, packing, !settings.slip_boundary);
    m.times.shear_geometry = seconds_since(t0);
  }
  return m;
}

LinearSystem build_linear_system(const PoreMesh& m, const BoundaryConditions& bc,
                                 const EngineSettings& settings, double dt, const CellOrdering* previous,
                                 std::unique_ptr<CholmodSolver> solver) {
  LinearSystem l;
  if (solver) l.cholmod = std::move(solver);
  l.dt = dt;
  l.mixed_precision = settings.mixed_precision;
  l.mixed_precision_min_entries = settings.mixed_precision_min_entries;
  if (settings.fluid_bulk_modulus > 0) {
    l.storage.resize(m.mesh().n_cells());
    for (int c = 0; c < m.mesh().n_cells(); ++c)
      l.storage[c] = m.cells.fluid_volume[c] / (settings.fluid_bulk_modulus * dt);
  }
  for (const auto& c : bc.imposed_pressure) l.imposed_pressure_cells.push_back(m.tri.locate(c.position));
  for (const auto& c : bc.imposed_flux) l.imposed_flux_cells.push_back(m.tri.locate(c.position));

  auto t0 = Clock::now();
  l.system = assemble_pressure_system(m.mesh(), m.facets, m.k, bc, l.imposed_pressure_cells, l.storage);
  const PressureSystem& s = l.system;
  for (int u = 0; u < s.n_unknowns(); ++u) {
    const int c = s.unknown_cell[u];
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e)
      if (s.unknown[s.adj_cell[e]] < 0) {
        l.coupling_unknown.push_back(u);
        l.coupling_cell.push_back(s.adj_cell[e]);
        l.coupling_k.push_back(s.adj_k[e]);
      }
  }
  l.times.assembly = seconds_since(t0);

  t0 = Clock::now();
  if (settings.use_solver == 3 && s.n_unknowns() > 0) {
    GivenOrdering given;
    if (previous && settings.reuse_ordering) {
      given.perm = previous->carry_over(m.mesh(), s);
      given.max_fill = settings.max_fill_growth * previous->fresh_fill();
      given.from_metis = previous->from_metis();
    }
    CholmodSolver& f = *l.cholmod;
    f.set_openmp_teams(settings.cholmod_openmp_teams);
    f.factorize(s, settings.force_metis ? Ordering::kMetis : settings.ordering,
                settings.mixed_precision ? FactorPrecision::kScaled32 : FactorPrecision::kDouble, given,
                settings.mixed_precision_min_entries);
    if (f.reduced_precision()) index_rows(l.system);  // for the refinement's residual; a double factor never reads them
    if (f.ready() && f.permutation())
      l.ordering = std::make_shared<const CellOrdering>(m.mesh(), s, f.permutation(), f.chains(),
                                                        f.ordering_given() ? previous->fresh_fill() : f.fill(),
                                                        f.metis_used());
  }
  if (settings.use_solver == 1 && s.n_unknowns() > 0) l.pcg.setup(s);
  l.times.analysis = l.cholmod->analysis_seconds();
  l.times.factorization = seconds_since(t0) - l.times.analysis;
  return l;
}

}  // namespace pfv
