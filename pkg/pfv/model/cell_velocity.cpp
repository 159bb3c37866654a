#include "pfv/model/cell_velocity.hpp"

namespace pfv {

std::vector<Vec3> mean_cell_velocities(const CellGeometry& cells, const FacetGeometry& facets,
                                       const std::vector<double>& conductance, const std::vector<double>& pressure) {
  std::vector<Vec3> v(cells.volume.size(), Vec3::Zero());
  for (int f = 0; f < facets.size(); ++f) {
    const int a = facets.cell[f][0], b = facets.cell[f][1];
    if (a < 0 || b < 0 || conductance[f] == 0) continue;
    const double q = conductance[f] * (pressure[a] - pressure[b]);  // from a to b
    const Vec3 half = 0.5 * (cells.power_centre[b] - cells.power_centre[a]);
    // Both cells see the flux cross at the same point: +q from a, -q into b, measured from
    // their own centres (P_a + half = P_b - half).
    v[a] += q * half;
    v[b] += q * half;
  }
  for (std::size_t c = 0; c < v.size(); ++c) {
    const double volume = cells.fluid_volume[c];
    v[c] = volume > 0 ? Vec3(v[c] / volume) : Vec3::Zero();
  }
  return v;
}

}  // namespace pfv
