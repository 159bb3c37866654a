#include "pfv/linalg/gauss_seidel_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pfv {
namespace {

// Sweeps until the relative change max|dp| / max|p| falls below tolerance; b already holds the
// couplings to the Dirichlet cells, so only unknown neighbours are read.
SolveStats sweep(const MatrixRows& g, const std::vector<double>& b, std::vector<double>& x, double tolerance,
                 double relax, int max_iterations) {
  SolveStats r;
  const int nu = static_cast<int>(g.diagonal.size());
  const int w = g.width;
  if (nu == 0) return r;
  r.converged = false;
  while (r.sweeps < max_iterations) {
    double max_change = 0, max_p = 0;
    for (int u = 0; u < nu; ++u) {
      const int* column = g.column.data() + static_cast<std::size_t>(u) * w;
      const double* value = g.value.data() + static_cast<std::size_t>(u) * w;
      double sum = b[u];
      for (int f = 0; f < w; ++f) sum -= value[f] * x[column[f]];  // padding: (u, 0)
      const double dp = relax * (sum / g.diagonal[u] - x[u]);
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

void GaussSeidelSolver::setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions&) {
  rows_ = index_rows(*g);
}

SolveStats GaussSeidelSolver::solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) {
  return sweep(rows_, b, x, control.tolerance, control.relax, control.max_iterations);
}

void GaussSeidelSolver::apply_inverse(const std::vector<double>& b, std::vector<double>& x,
                                      const SolveControl& control) const {
  x.assign(rows_.diagonal.size(), 0.0);
  sweep(rows_, b, x, control.inverse_tolerance, control.relax, control.max_iterations);
}

}  // namespace pfv
