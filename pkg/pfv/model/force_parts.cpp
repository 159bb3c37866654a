#include "pfv/model/force_parts.hpp"

#include "pfv/model/force_terms.hpp"

namespace pfv {

ForceParts split_fluid_forces(const Mesh& mesh, const FacetGeometry& facets, const Packing& packing,
                              const std::vector<double>& p) {
  const int nv = mesh.n_spheres + kWallCount;
  ForceParts out;
  out.pressure.assign(nv, Vec3::Zero());
  out.viscous.assign(nv, Vec3::Zero());
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const auto footprint = wall_footprints(mesh, c, packing);
    for (int l = 0; l < 4; ++l) out.pressure[mesh.cell_vertices[c][l]] += p[c] * footprint[l];
  }
  for (int f = 0; f < facets.size(); ++f) {
    const auto terms = facet_force_terms(mesh, facets, f);
    if (!terms) continue;
    double dp = 0;  // pressure of cell 0 minus that beyond (the normal points out of cell 0)
    for (int side = 0; side < 2; ++side) {
      const int c = facets.cell[f][side];
      if (c >= 0) dp += side == 0 ? p[c] : -p[c];
    }
    for (int s = 0; s < 3; ++s) {
      const int v = facets.vertex[f][s];
      out.pressure[v] += (dp * terms->pressure[s]) * terms->normal;
      out.viscous[v] += (dp * terms->viscous[s]) * terms->normal;
    }
  }
  return out;
}

}  // namespace pfv
