#include "pfv/model/conductance.hpp"

#include <algorithm>
#include <cmath>

namespace pfv {

std::vector<double> throat_conductances(const FacetGeometry& f, const ConductanceModel& m) {
  const int n = f.size();
  std::vector<double> k(n, 0.0);
  const double alpha = 0.5 * m.permeability_factor;
  std::vector<double> finite;
  finite.reserve(n);
  for (int i = 0; i < n; ++i) {
    if (f.cell[i][1] < 0) continue;
    const double rh = f.hydraulic_radius[i];
    const double g = alpha * f.fluid_area[i] * rh * rh / m.viscosity;
    const double length = f.length[i] + (m.entrance > 0 ? m.entrance * std::sqrt(f.fluid_area[i] / M_PI) : 0.0);
    k[i] = length > 0 ? g / length : HUGE_VAL;
    if (std::isfinite(k[i])) finite.push_back(k[i]);
  }
  if (!m.clamp) {
    for (double& x : k)
      if (!std::isfinite(x)) x = 0.0;  // a zero-length throat cannot be given a value
    return k;
  }
  // The reference is the median, not the mean: a few near-flat cells (L -> 0) inflate the
  // mean by orders of magnitude and would disable the upper bound exactly when it matters.
  double reference = 0;
  if (!finite.empty()) {
    auto mid = finite.begin() + finite.size() / 2;
    std::nth_element(finite.begin(), mid, finite.end());
    reference = *mid;
  }
  for (int i = 0; i < n; ++i)
    if (f.cell[i][1] >= 0) k[i] = std::clamp(k[i], m.min_ratio * reference, m.max_ratio * reference);
  return k;
}

}  // namespace pfv
