#include "gauss_seidel_solver.hpp"

#include <algorithm>
#include <cmath>

#include "pressure_system.hpp"

namespace pfv {

GaussSeidelResult gauss_seidel(const PressureSystem& s, const std::vector<double>& rhs,
                               std::vector<double>& p, double tolerance, double relax,
                               int max_iterations) {
  GaussSeidelResult r;
  const int nu = s.n_unknowns();
  if (nu == 0) {
    r.converged = true;
    return r;
  }
  while (r.iterations < max_iterations) {
    double max_change = 0, max_p = 0;
    for (int u = 0; u < nu; ++u) {
      const int c = s.unknown_cell[u];
      double sum = rhs[u];
      for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) sum += s.adj_k[e] * p[s.adj_cell[e]];
      const double dp = relax * (sum / s.diagonal[c] - p[c]);
      p[c] += dp;
      max_change = std::max(max_change, std::abs(dp));
      max_p = std::max(max_p, std::abs(p[c]));
    }
    ++r.iterations;
    r.relative_change = max_p > 0 ? max_change / max_p : max_change;
    if (r.relative_change < tolerance) {
      r.converged = true;
      break;
    }
  }
  return r;
}

}  // namespace pfv
