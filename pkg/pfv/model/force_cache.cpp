#include "pfv/model/force_cache.hpp"

#include <numeric>

#include "pfv/common/parallel.hpp"
#include "pfv/model/force_terms.hpp"

namespace pfv {
namespace {

// The local index in cell[f][side] of facet vertex v (a vertex of cell[f][0]): v itself, but in
// the far cell of a periodic mesh, where the facet's vertices are other images of the same
// spheres, the vertex that the facet's translation carries onto v.
int local_of(const Mesh& mesh, const FacetGeometry& facets, const Packing& packing, int f, int side, int v) {
  const int c = facets.cell[f][side];
  if (side == 0 || facets.translation.empty()) {
    for (int l = 0; l < 4; ++l)
      if (mesh.cell_vertices[c][l] == v) return l;
    return -1;
  }
  const Vec3 x = packing.centre[v] - facets.translation[f];
  int best = -1;
  double nearest = 0;
  for (int l = 0; l < 4; ++l) {
    if (l == facets.local[f][1]) continue;
    const double d = (packing.centre[mesh.cell_vertices[c][l]] - x).squaredNorm();
    if (best < 0 || d < nearest) best = l, nearest = d;
  }
  return best;
}

}  // namespace

void ForceCache::build(const Mesh& mesh, const FacetGeometry& facets, const Packing& packing) {
  const int nc = mesh.n_cells();
  std::vector<std::array<Vec3, 4>> per_cell(nc);
#pragma omp parallel for schedule(static) if (nc > kMinParallelLoop)
  for (int c = 0; c < nc; ++c) per_cell[c] = wall_footprints(mesh, c, packing);

  for (int f = 0; f < facets.size(); ++f) {
    const auto terms = facet_force_terms(mesh, facets, f);
    if (!terms) continue;
    const Vec3& n = terms->normal;
    std::array<double, 3> coef;
    for (int s = 0; s < 3; ++s) coef[s] = terms->pressure[s] + terms->viscous[s];
    for (int side = 0; side < 2; ++side) {
      const int c = facets.cell[f][side];
      if (c < 0) continue;
      const double sign = side == 0 ? 1.0 : -1.0;  // n points out of cell 0
      for (int s = 0; s < 3; ++s) {
        const int l = local_of(mesh, facets, packing, f, side, facets.vertex[f][s]);
        if (l >= 0) per_cell[c][l] += sign * coef[s] * n;
      }
    }
  }

  const int nv = mesh.n_spheres + kWallCount;
  start_.assign(nv + 1, 0);
  for (int c = 0; c < nc; ++c)
    for (int v : mesh.cell_vertices[c]) ++start_[v + 1];
  std::partial_sum(start_.begin(), start_.end(), start_.begin());
  cell_.resize(start_[nv]);
  unit_.resize(start_[nv]);
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (int c = 0; c < nc; ++c)
    for (int l = 0; l < 4; ++l) {
      const int v = mesh.cell_vertices[c][l];
      cell_[fill[v]] = c;
      unit_[fill[v]++] = per_cell[c][l];
    }
}

void ForceCache::apply(const std::vector<double>& p, std::vector<Vec3>& force, bool team) const {
  const int nv = n_vertices();
  force.resize(nv);
  // The work is one term per (sphere, incident cell), about 23 per sphere: 10 000 spheres are
  // worth a team, though fewer than kMinParallelLoop loop items.
#pragma omp parallel for schedule(static) if (team && start_[nv] > kMinParallelLoop)
  for (int v = 0; v < nv; ++v) {
    Vec3 f = Vec3::Zero();
    for (int e = start_[v]; e < start_[v + 1]; ++e) f += p[cell_[e]] * unit_[e];
    force[v] = f;
  }
}

void ForceCache::apply_magnitude(const std::vector<double>& value, std::vector<Vec3>& bound) const {
  const int nv = n_vertices();
  bound.resize(nv);
  for (int v = 0; v < nv; ++v) {
    Vec3 b = Vec3::Zero();
    for (int e = start_[v]; e < start_[v + 1]; ++e) b += value[cell_[e]] * unit_[e].cwiseAbs();
    bound[v] = b;
  }
}

}  // namespace pfv
