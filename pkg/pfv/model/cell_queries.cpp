#include "pfv/model/cell_queries.hpp"

namespace pfv {

Vec3 cell_barycenter(const CellShape& s, const Packing& pk) {
  const int n_real = 4 - s.n_walls;
  Vec3 spheres = Vec3::Zero();
  for (int i = 0; i < n_real; ++i) spheres += pk.centre[s.v[i]];
  Vec3 sum = spheres;
  spheres /= n_real;
  for (int i = n_real; i < 4; ++i) sum += pk.walls.project(s.v[i], spheres);
  return sum / 4.0;
}

double cell_flux(const PressureSystem& s, const std::vector<double>& p, const std::vector<double>& volume_rate, int c) {
  double q = 0;
  for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) q += s.adj_k[e] * (p[c] - p[s.adj_cell[e]]);
  if (static_cast<std::size_t>(c) < volume_rate.size()) q += volume_rate[c];
  return q;
}

}  // namespace pfv
