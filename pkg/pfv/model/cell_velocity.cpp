#include "pfv/model/cell_velocity.hpp"

namespace pfv {

std::vector<Vec3> mean_cell_velocities(const CellGeometry& cells, const FacetGeometry& facets,
                                       const std::vector<double>& conductance, const std::vector<double>& pressure,
                                       const std::vector<Vec3>& centre, int n_spheres) {
  std::vector<Vec3> v(cells.volume.size(), Vec3::Zero());
  for (int f = 0; f < facets.size(); ++f) {
    const int a = facets.cell[f][0], b = facets.cell[f][1];
    if (a < 0 || b < 0 || conductance[f] == 0) continue;
    const Vec3 &pa = cells.power_centre[a], &pb = cells.power_centre[b];
    const double length = (pb - pa).norm();
    if (!(length > 0)) continue;
    const Vec3 axis = (pb - pa) / length;
    int sphere = facets.vertex[f][0];  // a facet has at least one sphere: a point of its plane
    for (int x : facets.vertex[f])
      if (x < n_spheres) sphere = x;
    const double q = conductance[f] * (pressure[a] - pressure[b]);  // from a to b
    const Vec3 from_a = (centre[sphere] - pa).dot(axis) * axis;     // X_f - P_a
    // +q leaves a at X_f, -q leaves b there: q (X_f - P_a) and -q (X_f - P_b).
    v[a] += q * from_a;
    v[b] += q * (pb - pa - from_a);
  }
  for (std::size_t c = 0; c < v.size(); ++c) {
    const double volume = cells.fluid_volume[c];
    v[c] = volume > 0 ? Vec3(v[c] / volume) : Vec3::Zero();
  }
  return v;
}

}  // namespace pfv
