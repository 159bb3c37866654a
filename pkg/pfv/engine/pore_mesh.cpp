#include "pfv/engine/pore_mesh.hpp"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "pfv/common/stage_timer.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace pfv {
namespace {

// Multiplies R_h of every throat with wall vertices by YADE's multSym1 = 2^-1/4 (one wall
// vertex) or multSym2 = 4^-1/4 (two or more) and returns the (facet, original R_h) pairs.
std::vector<std::pair<int, double>> apply_yade_wall_throat_factor(const Mesh& mesh, FacetGeometry& facets) {
  const double one_wall = std::pow(2.0, -0.25), two_walls = std::pow(4.0, -0.25);
  std::vector<std::pair<int, double>> saved;
  for (int f = 0; f < facets.size(); ++f) {
    int walls = 0;
    for (int v : facets.vertex[f]) walls += mesh.is_wall(v) ? 1 : 0;
    if (walls == 0) continue;
    saved.emplace_back(f, facets.hydraulic_radius[f]);
    facets.hydraulic_radius[f] *= walls == 1 ? one_wall : two_walls;
  }
  return saved;
}

}  // namespace

bool MeshRecipe::stale_for(const EngineSettings& s) const {
  const ConductanceModel& a = conductance;
  const ConductanceModel& b = s.conductance;
  return a.permeability_factor != b.permeability_factor || a.entrance != b.entrance || a.clamp != b.clamp ||
         a.min_ratio != b.min_ratio || a.max_ratio != b.max_ratio || slip_boundary != s.slip_boundary ||
         (s.viscous_shear && !viscous_shear) || yade_wall_throat_factor != s.yade_wall_throat_factor;
}

void PoreMesh::set_viscosity(double mu) {
  const double scale = recipe.conductance.viscosity / mu;
  for (double& x : k) x *= scale;
  recipe.conductance.viscosity = mu;
}

PoreMesh build_pore_mesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                         const EngineSettings& settings) {
  check_distinct_centres(centres);

  PoreMesh m(settings);
  m.source = MeshSource{centres, radii, walls};
  auto t0 = StageClock::now();
  const Mesh& mesh = m.tri.build(centres, radii, walls);
  const auto inside = m.tri.centres_inside_neighbours(centres, radii);
  if (!inside.empty())
    throw std::invalid_argument("sphere " + std::to_string(inside[0].first) + " and sphere " +
                                std::to_string(inside[0].second) +
                                " overlap so much that one centre lies inside the other sphere (" +
                                std::to_string(inside.size()) + " such pairs); the pore mesh would be degenerate");
  if (mesh.n_cells() == 0) throw std::invalid_argument("the triangulation has no pore cell");
  m.times.triangulation = seconds_since(t0);

  t0 = StageClock::now();
  const Packing packing{centres, radii, walls};
  m.cells = compute_cell_geometry(mesh, packing);
  m.facets = compute_facet_geometry(mesh, m.cells, packing, settings.slip_boundary);
  m.mean_cell_volume = std::accumulate(m.cells.volume.begin(), m.cells.volume.end(), 0.0) / mesh.n_cells();
  m.times.geometry = seconds_since(t0);

  t0 = StageClock::now();
  if (settings.slip_boundary && settings.yade_wall_throat_factor) {
    // YADE's factor acts on the conductance only: the scaled R_h are restored afterwards, so
    // that the viscous shear term sees the geometric R_h.
    const auto saved = apply_yade_wall_throat_factor(mesh, m.facets);
    m.k = throat_conductances(m.facets, settings.conductance);
    for (const auto& [f, rh] : saved) m.facets.hydraulic_radius[f] = rh;
  } else {
    m.k = throat_conductances(m.facets, settings.conductance);
  }
  m.times.conductance = seconds_since(t0);

  t0 = StageClock::now();
  m.cache.build(mesh, m.facets, packing);
  m.times.force_cache = seconds_since(t0);

  if (settings.viscous_shear) {
    t0 = StageClock::now();
    m.shear = build_viscous_shear(mesh, m.cells, m.facets, packing, !settings.slip_boundary);
    m.times.shear_geometry = seconds_since(t0);
  }
  return m;
}

}  // namespace pfv
