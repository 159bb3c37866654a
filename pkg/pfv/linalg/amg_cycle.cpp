#include "pfv/linalg/amg_cycle.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "pfv/common/parallel.hpp"

namespace pfv {
namespace {

bool on_team(bool team, int n) { return team && n >= kMinParallelLoop; }

void check_rows(const CsrRows& m, const char* what) {
  const bool ok = static_cast<int>(m.start.size()) == m.n_rows + 1 && m.start.front() == 0 &&
                  m.start.back() == static_cast<int>(m.column.size()) && m.column.size() == m.value.size() &&
                  std::all_of(m.column.begin(), m.column.end(), [&](int c) { return c >= 0 && c < m.n_cols; });
  if (!ok) throw std::invalid_argument(std::string("the multigrid cycle was given inconsistent rows of ") + what);
}

CsrRows transpose(const CsrRows& m) {
  CsrRows t;
  t.n_rows = m.n_cols;
  t.n_cols = m.n_rows;
  t.start.assign(t.n_rows + 1, 0);
  for (int c : m.column) ++t.start[c + 1];
  for (int i = 0; i < t.n_rows; ++i) t.start[i + 1] += t.start[i];
  t.column.resize(m.column.size());
  t.value.resize(m.value.size());
  std::vector<int> next(t.start.begin(), t.start.end() - 1);
  for (int i = 0; i < m.n_rows; ++i)  // rows in order: each transposed row's columns ascend
    for (int e = m.start[i]; e < m.start[i + 1]; ++e) {
      const int slot = next[m.column[e]]++;
      t.column[slot] = i;
      t.value[slot] = m.value[e];
    }
  return t;
}

// y = alpha M x + beta y, row by row: each row's sum in the same order on any thread. One chain
// of additions: with four to six entries per row, two interleaved sums made the sweeps slower.
void multiply_rows(const int* start, const int* column, const double* value, int n, double alpha, const double* x,
                   double beta, double* y, bool team) {
#pragma omp parallel for schedule(static) if (on_team(team, n))
  for (int i = 0; i < n; ++i) {
    double s = 0;
    for (int e = start[i]; e < start[i + 1]; ++e) s += value[e] * x[column[e]];
    y[i] = beta == 0 ? alpha * s : alpha * s + beta * y[i];
  }
}

void multiply_rows(const CsrRows& m, double alpha, const double* x, double beta, double* y, bool team) {
  multiply_rows(m.start.data(), m.column.data(), m.value.data(), m.n_rows, alpha, x, beta, y, team);
}

}  // namespace

double fixed_chunk_dot(const double* a, const double* b, int n, bool team) {
  std::array<double, kSumChunks> part{};
#pragma omp parallel for schedule(static) if (on_team(team, n))
  for (int k = 0; k < kSumChunks; ++k) {
    double s = 0;
    for (int i = chunk_begin(n, k); i < chunk_begin(n, k + 1); ++i) s += a[i] * b[i];
    part[k] = s;
  }
  double sum = 0;
  for (double s : part) sum += s;
  return sum;
}

struct AmgCycle::Coarsest {
  Eigen::LDLT<Eigen::MatrixXd> ldlt;  // empty beyond kMaxDenseRows
  bool dense = false;
};

AmgCycle::AmgCycle(std::vector<CsrRows> a, std::vector<CsrRows> p, MultigridSmoother smoother)
    : coarsest_(std::make_unique<Coarsest>()), smoother_(smoother) {
  if (a.empty() || p.size() + 1 != a.size())
    throw std::invalid_argument("the multigrid cycle needs one interpolation fewer than levels");
  levels_.resize(a.size());
  for (std::size_t l = 0; l < a.size(); ++l) {
    Level& level = levels_[l];
    level.a = std::move(a[l]);
    check_rows(level.a, "a level's matrix");
    if (level.a.n_rows != level.a.n_cols || level.a.n_rows <= 0)
      throw std::invalid_argument("a level's matrix of the multigrid cycle is not square");
    if (l + 1 < levels_.size()) {
      level.p = std::move(p[l]);
      check_rows(level.p, "an interpolation");
      if (level.p.n_rows != level.a.n_rows || level.p.n_cols != a[l + 1].n_rows)
        throw std::invalid_argument("an interpolation of the multigrid cycle does not join its two levels");
      level.r = transpose(level.p);
    }
    if (l == 0) system_column_ = level.a.column;
    const int n = level.n();
    const int blocks = std::clamp(n / kRowsPerBlock, 1, kMaxBlocks);
    level.block_start.resize(blocks + 1);
    for (int k = 0; k <= blocks; ++k) level.block_start[k] = static_cast<int>(static_cast<long long>(n) * k / blocks);
    level.inverse_diagonal.resize(n);
    std::vector<int> halo_slot(n, -1);
    for (int k = 0; k < blocks; ++k) {
      const int lo = level.block_start[k], hi = level.block_start[k + 1];
      for (int i = lo; i < hi; ++i) {
        double d = 0, diagonal = 0;
        for (int e = level.a.start[i]; e < level.a.start[i + 1]; ++e) {
          int& j = level.a.column[e];
          const bool in_block = j >= lo && j < hi;
          if (j == i)
            diagonal += level.a.value[e];
          else if (smoother == MultigridSmoother::kJacobi || !in_block)
            d += std::abs(level.a.value[e]);
          if (in_block) continue;
          if (halo_slot[j] < 0) {
            halo_slot[j] = static_cast<int>(level.halo.size());
            level.halo.push_back(j);
          }
          j = n + halo_slot[j];
        }
        if (!(diagonal > 0) || !std::isfinite(d))
          throw std::invalid_argument("a level's matrix of the multigrid cycle has a row without a positive diagonal");
        level.inverse_diagonal[i] = 1 / (diagonal + d);
      }
    }
    level.a.n_cols = n + static_cast<int>(level.halo.size());
    level.x_ext.resize(level.a.n_cols);
    if (l > 0) level.b.resize(n);
    level.work.resize(smoother == MultigridSmoother::kJacobi ? level.a.n_cols : n);
  }
  const Level& last = levels_.back();
  if (last.n() <= kMaxDenseRows) {
    Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(last.n(), last.n());
    for (int i = 0; i < last.n(); ++i)
      for (int e = last.a.start[i]; e < last.a.start[i + 1]; ++e) {
        const int c = last.a.column[e];
        dense(i, c < last.n() ? c : last.halo[c - last.n()]) += last.a.value[e];
      }
    coarsest_->ldlt.compute(dense);
    coarsest_->dense = true;
  }
}

AmgCycle::~AmgCycle() = default;

double AmgCycle::operator_complexity() const {
  double all = 0;
  for (const Level& level : levels_) all += static_cast<double>(level.a.value.size());
  return all / static_cast<double>(levels_.front().a.value.size());
}

void AmgCycle::multiply(double alpha, const double* x, double beta, double* y, bool team) const {
  const CsrRows& a = levels_.front().a;
  multiply_rows(a.start.data(), system_column_.data(), a.value.data(), a.n_rows, alpha, x, beta, y, team);
}

// The halo's values from x: what the rows outside each block read.
void AmgCycle::refresh_halo(const Level& level, bool team) const {
  double* x = level.x_ext.data();
  const int n = level.n(), h = static_cast<int>(level.halo.size());
#pragma omp parallel for schedule(static) if (on_team(team, h))
  for (int k = 0; k < h; ++k) x[n + k] = x[level.halo[k]];
}

// x += D^-1 (b - A x) row by row, Gauss-Seidel inside each block: a row reads the new values of
// its block's rows before it and, outside its block, the values before the sweep (the halo).
// from_zero: x = 0 on entry.
void AmgCycle::sweep(const Level& level, const double* b, bool forward, bool from_zero, bool team) const {
  const CsrRows& a = level.a;
  const int blocks = static_cast<int>(level.block_start.size()) - 1;
  if (from_zero)
    std::fill(level.x_ext.begin(), level.x_ext.end(), 0.0);
  else
    refresh_halo(level, team);
  double* x = level.x_ext.data();
  const int* start = a.start.data();
  const int* column = a.column.data();
  const double* value = a.value.data();
  const double* inverse_diagonal = level.inverse_diagonal.data();
#pragma omp parallel for schedule(static) if (on_team(team, level.n()))
  for (int k = 0; k < blocks; ++k) {
    const int lo = level.block_start[k], hi = level.block_start[k + 1];
    for (int step = 0; step < hi - lo; ++step) {
      const int i = forward ? lo + step : hi - 1 - step;
      double r = b[i];
      for (int e = start[i]; e < start[i + 1]; ++e) r -= value[e] * x[column[e]];
      x[i] += r * inverse_diagonal[i];
    }
  }
}

void AmgCycle::jacobi(const Level& level, const double* b, bool from_zero, bool team) const {
  const CsrRows& a = level.a;
  const int n = level.n();
  const bool par = on_team(team, n);
  double* x = level.x_ext.data();
  if (from_zero) {
#pragma omp parallel for schedule(static) if (par)
    for (int i = 0; i < n; ++i) x[i] = b[i] * level.inverse_diagonal[i];
    return;
  }
  refresh_halo(level, team);
  double* before = level.work.data();
#pragma omp parallel for schedule(static) if (par)
  for (int i = 0; i < a.n_cols; ++i) before[i] = x[i];
#pragma omp parallel for schedule(static) if (par)
  for (int i = 0; i < n; ++i) {
    double r = b[i];
    for (int e = a.start[i]; e < a.start[i + 1]; ++e) r -= a.value[e] * before[a.column[e]];
    x[i] = before[i] + r * level.inverse_diagonal[i];
  }
}

// The pre-smoother (down, from zero) or the post-smoother (up), its adjoint.
void AmgCycle::smooth(const Level& level, const double* b, bool down, bool team) const {
  switch (smoother_) {
    case MultigridSmoother::kGaussSeidel:  // the symmetric pair is its own adjoint
      sweep(level, b, true, down, team);
      sweep(level, b, false, false, team);
      break;
    case MultigridSmoother::kSplitGaussSeidel:
      sweep(level, b, down, down, team);
      break;
    case MultigridSmoother::kJacobi:
      jacobi(level, b, down, team);
      break;
  }
}

void AmgCycle::solve_coarsest(const double* b, bool team) const {
  const Level& last = levels_.back();
  const int n = last.n();
  if (coarsest_->dense) {
    Eigen::Map<Eigen::VectorXd>(last.x_ext.data(), n) = coarsest_->ldlt.solve(Eigen::Map<const Eigen::VectorXd>(b, n));
    return;
  }
  for (int s = 0; s < kCoarsestSweeps; ++s) {  // symmetric: each pair is its own adjoint
    sweep(last, b, true, s == 0, team);
    sweep(last, b, false, false, team);
  }
}

void AmgCycle::apply(const double* r, double* z, bool team) const {
  const int last = levels() - 1;
  const auto b_of = [&](int l) { return l == 0 ? r : levels_[l].b.data(); };  // level 0: the caller's r
  for (int l = 0; l < last; ++l) {
    const Level& level = levels_[l];
    smooth(level, b_of(l), true, team);
    refresh_halo(level, team);
    double* residual = level.work.data();
    std::copy(b_of(l), b_of(l) + level.n(), residual);
    multiply_rows(level.a, -1.0, level.x_ext.data(), 1.0, residual, team);
    multiply_rows(level.r, 1.0, residual, 0.0, levels_[l + 1].b.data(), team);
  }
  solve_coarsest(b_of(last), team);
  for (int l = last - 1; l >= 0; --l) {
    const Level& level = levels_[l];
    multiply_rows(level.p, 1.0, levels_[l + 1].x_ext.data(), 1.0, level.x_ext.data(), team);
    smooth(level, b_of(l), false, team);
  }
  const Level& top = levels_.front();
  std::copy(top.x_ext.begin(), top.x_ext.begin() + top.n(), z);
}

}  // namespace pfv
