#include "pfv/model/force_parts.hpp"

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
  // The same terms as ForceCache::build, kept apart.
  for (int f = 0; f < facets.size(); ++f) {
    const Vec3& S = facets.area_vector[f];
    const double area = S.norm();
    if (area <= 0) continue;
    const Vec3 n = S / area;
    const auto& wet = facets.wetted_area[f];
    const double wet_sum = wet[0] + wet[1] + wet[2];
    int spheres = 0;
    for (int v : facets.vertex[f]) spheres += mesh.is_wall(v) ? 0 : 1;
    double dp = 0;  // pressure of cell 0 minus that beyond (n points out of cell 0)
    for (int side = 0; side < 2; ++side) {
      const int c = facets.cell[f][side];
      if (c >= 0) dp += side == 0 ? p[c] : -p[c];
    }
    for (int s = 0; s < 3; ++s) {
      const int v = facets.vertex[f][s];
      const double share = wet_sum > 0 ? wet[s] / wet_sum : (mesh.is_wall(v) ? 0.0 : 1.0 / spheres);
      out.pressure[v] += (dp * facets.sector_area[f][s]) * n;
      out.viscous[v] += (dp * facets.fluid_area[f] * share) * n;
    }
  }
  return out;
}

}  // namespace pfv
