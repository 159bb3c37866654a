#include "conductance.hpp"

#include <algorithm>
#include <cmath>

namespace pfv {

std::vector<double> throat_conductances(const FacetGeometry& f, const ConductanceModel& m) {
  const int n = f.size();
  std::vector<double> k(n, 0.0);
  const double alpha = 0.5 * m.permeability_factor;
  double sum = 0;
  int count = 0;
  for (int i = 0; i < n; ++i) {
    if (f.cell[i][1] < 0) continue;
    const double rh = f.hydraulic_radius[i];
    const double g = alpha * f.fluid_area[i] * rh * rh / m.viscosity;
    k[i] = f.length[i] > 0 ? g / f.length[i] : HUGE_VAL;
    if (std::isfinite(k[i])) {
      sum += k[i];
      ++count;
    }
  }
  if (!m.clamp) {
    for (double& x : k)
      if (!std::isfinite(x)) x = 0.0;  // a zero-length throat cannot be given a value
    return k;
  }
  const double mean = count > 0 ? sum / count : 0.0;
  for (int i = 0; i < n; ++i)
    if (f.cell[i][1] >= 0) k[i] = std::clamp(k[i], m.min_ratio * mean, m.max_ratio * mean);
  return k;
}

}  // namespace pfv
