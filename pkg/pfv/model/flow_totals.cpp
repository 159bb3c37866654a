#include "pfv/model/flow_totals.hpp"

namespace pfv {

double boundary_flux(const PressureSystem& s, const std::vector<double>& p, const std::vector<double>& volume_rate,
                     int wall) {
  double q = 0;
  for (std::size_t c = 0; c < s.source.size(); ++c) {
    if (!s.source[c].is_wall(wall)) continue;
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) q += s.adj_k[e] * (p[s.adj_cell[e]] - p[c]);
    if (c < volume_rate.size()) q -= volume_rate[c];
  }
  return q;
}

double imposed_flux_total(const PressureSystem& s, const std::vector<int>& cells,
                          const std::vector<PointCondition>& imposed_flux) {
  double q = 0;
  for (std::size_t i = 0; i < cells.size(); ++i)
    if (cells[i] >= 0 && s.unknown[cells[i]] >= 0) q += imposed_flux[i].value;
  return q;
}

double volume_rate_total(const std::vector<double>& volume_rate) {
  double s = 0;
  for (double r : volume_rate) s += r;
  return s;
}

double average_pressure(const std::vector<double>& pressure, const std::vector<double>& volume) {
  double pv = 0, v = 0;
  for (std::size_t c = 0; c < pressure.size(); ++c) {
    pv += pressure[c] * volume[c];
    v += volume[c];
  }
  return v > 0 ? pv / v : 0.0;
}

}  // namespace pfv
