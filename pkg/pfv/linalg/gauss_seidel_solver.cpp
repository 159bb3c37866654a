#include "pfv/linalg/gauss_seidel_solver.hpp"

#include <algorithm>
#include <cmath>

#include "pfv/model/pressure_system.hpp"

namespace pfv {
namespace {

// Sweeps until the relative change max|dp| / max|p| falls below tolerance; b already holds the
// couplings to the Dirichlet cells, so only unknown neighbours are read.
SolveStats sweep(const PressureSystem& s, const std::vector<double>& b, std::vector<double>& x, double tolerance,
                 double relax, int max_iterations) {
  SolveStats r;
  const int nu = s.n_unknowns();
  if (nu == 0) return r;
  r.converged = false;
  while (r.sweeps < max_iterations) {
    double max_change = 0, max_p = 0;
    for (int u = 0; u < nu; ++u) {
      const int c = s.unknown_cell[u];
      double sum = b[u];
      for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) {
        const int v = s.unknown[s.adj_cell[e]];
        if (v >= 0) sum += s.adj_k[e] * x[v];
      }
      const double dp = relax * (sum / s.diagonal[c] - x[u]);
      x[u] += dp;
      max_change = std::max(max_change, std::abs(dp));
      max_p = std::max(max_p, std::abs(x[u]));
    }
    ++r.sweeps;
    const double relative_change = max_p > 0 ? max_change / max_p : max_change;
    if (relative_change < tolerance) {
      r.converged = true;
      break;
    }
  }
  return r;
}

}  // namespace

SolveStats GaussSeidelSolver::solve(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                                    const SolveControl& control) {
  return sweep(system, b, x, control.tolerance, control.relax, control.max_iterations);
}

void GaussSeidelSolver::apply_inverse(const PressureSystem& system, const std::vector<double>& b,
                                      std::vector<double>& x, const SolveControl& control) const {
  x.assign(system.n_unknowns(), 0.0);
  sweep(system, b, x, control.inverse_tolerance, control.relax, control.max_iterations);
}

}  // namespace pfv
