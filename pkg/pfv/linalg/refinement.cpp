#include "pfv/linalg/refinement.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "pfv/common/parallel.hpp"
#include "pfv/linalg/cholmod_solver.hpp"

namespace pfv {
namespace {

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// r = b - G x from G's rows; W > 0 fixes the width at compile time.
template <int W>
void residual_by_rows(const MatrixRows& s, const std::vector<double>& b, const std::vector<double>& x,
                      std::vector<double>& r, bool team) {
  const int n = static_cast<int>(s.diagonal.size());
  const int w = W > 0 ? W : s.width;
  r.resize(n);
#pragma omp parallel for schedule(static) if (team && n > kMinParallelLoop)
  for (int u = 0; u < n; ++u) {
    const int* column = s.column.data() + static_cast<std::size_t>(u) * w;
    const double* value = s.value.data() + static_cast<std::size_t>(u) * w;
    double gx = s.diagonal[u] * x[u];
    for (int f = 0; f < w; ++f) gx += value[f] * x[column[f]];
    r[u] = b[u] - gx;
  }
}

}  // namespace

void residual(const SymmetricMatrix& s, const MatrixRows& rows, const std::vector<double>& b,
              const std::vector<double>& x, std::vector<double>& r, LoopChoice* choice) {
  const int n = s.size();
  if (static_cast<int>(rows.diagonal.size()) == n && n > 0) {
    const bool team = choice ? choice->team(n) : true;
    const auto start = std::chrono::steady_clock::now();
    if (rows.width == 4)
      residual_by_rows<4>(rows, b, x, r, team);
    else
      residual_by_rows<0>(rows, b, x, r, team);
    if (choice) choice->done(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return;
  }
  r.assign(b.begin(), b.end());
  for (int j = 0; j < n; ++j) {
    const double xj = x[j];
    double column = 0;  // (G x)_j from the stored upper part of column j
    for (int e = s.col_start[j]; e < s.col_start[j + 1]; ++e) {
      const int i = s.row[e];
      const double g = s.value[e];
      column += g * x[i];
      if (i != j) r[i] -= g * xj;  // the symmetric lower entry
    }
    r[j] -= column;
  }
}

double Refinement::estimate_contraction(const SymmetricMatrix& s, const MatrixRows& rows, CholmodSolver& m) {
  // Power iteration on E = I - M^-1 G from a pseudo-random start that has a component along
  // every eigenvector; the ratio of successive norms tends to rho(E) from below.
  const int n = s.size();
  std::vector<double>& v = correction_;
  std::vector<double> zero(n, 0.0), gv;
  v.resize(n);
  for (int i = 0; i < n; ++i) v[i] = std::sin(1.0 + 2.7 * i);
  double norm = max_abs(v), ratio = 0;
  for (int it = 0; it < kPowerIterations; ++it) {
    for (double& x : v) x /= norm;
    residual(s, rows, zero, v, residual_, &residual_loop_);  // -G v
    m.solve(residual_, gv);                                  // -M^-1 G v
    for (int i = 0; i < n; ++i) v[i] += gv[i];
    const double next = max_abs(v);
    ratio = next;  // |E v| / |v| with |v| = 1
    if (next == 0) break;
    norm = next;
  }
  return ratio;
}

bool Refinement::solve(const SymmetricMatrix& s, const MatrixRows& rows, CholmodSolver& m, const std::vector<double>& b,
                       std::vector<double>& x, double tolerance, int max_passes) {
  // Corrections this small (relative to x) are round-off: their ratios say nothing about rho.
  constexpr double kRoundOff = 1e-13;
  if (rho_ < 0) rho_ = seed_ > 0 ? seed_ : std::max(kSafety * estimate_contraction(s, rows, m), 1e-12);
  if (rho_ >= 0.5) return false;
  double previous = 0;
  passes_ = 0;
  while (passes_ < max_passes) {
    residual(s, rows, b, x, residual_, &residual_loop_);
    m.solve(residual_, correction_);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += correction_[i];
    ++passes_;
    const double d = max_abs(correction_), scale = max_abs(x);
    if (d <= kRoundOff * scale) return true;
    // The tolerance is relative to the spread of the pressures, not to their size: forces and
    // fluxes depend on differences, and a large common offset (pZero, a deep hydrostatic
    // level) would otherwise let the differences carry a large relative error.
    const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
    const double spread = *hi - *lo > 0 ? *hi - *lo : scale;
    if (passes_ > 1 && previous > 1e3 * kRoundOff * scale) {
      rho_ = std::max(rho_, d / previous);  // a pass that contracted less than estimated
      if (rho_ >= 0.5) return false;
    }
    previous = d;
    if (rho_ / (1 - rho_) * d <= tolerance * spread) return true;
  }
  return false;
}

}  // namespace pfv
