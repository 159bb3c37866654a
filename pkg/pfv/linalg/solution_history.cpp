#include "pfv/linalg/solution_history.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "pfv/common/parallel.hpp"

namespace pfv {
namespace {

constexpr int kMax = 4;  // entries the per-row tables below hold

// Weights of the polynomial through (t[j], x_j), j = 0 ... order, at time target (Lagrange).
std::array<double, kMax> lagrange(const std::array<double, kMax>& t, int order, double target) {
  std::array<double, kMax> w{};
  for (int j = 0; j <= order; ++j) {
    w[j] = 1;
    for (int i = 0; i <= order; ++i)
      if (i != j) w[j] *= (target - t[i]) / (t[j] - t[i]);
  }
  return w;
}

}  // namespace

SolutionHistory::SolutionHistory(MPI_Comm comm, int n, int capacity) : comm_(comm), n_(n) {
  if (capacity < 0 || capacity > kMax) throw std::invalid_argument("a solution history keeps 0 to 4 solutions");
  x_.assign(capacity, std::vector<double>(n));
  time_.assign(capacity, 0.0);
  step_.assign(capacity, 0.0);
  gx_.assign(capacity, std::vector<double>(n));
}

bool SolutionHistory::on_team() const { return team_ && n_ >= kMinParallelLoop; }

bool SolutionHistory::equals_newest(const double* v) const {
  const double* x = newest().data();
  int local = 1, global = 0;
#pragma omp parallel for schedule(static) reduction(min : local) if (on_team())
  for (int i = 0; i < n_; ++i) local = std::min(local, x[i] == v[i] ? 1 : 0);
  MPI_Allreduce(&local, &global, 1, MPI_INT, MPI_MIN, comm_);
  return global == 1;
}

void SolutionHistory::drop_newest() {
  head_ = (head_ + capacity() - 1) % capacity();
  --count_;
}

bool SolutionHistory::adopt_start(const double* start) {
  if (capacity() == 0) return false;
  if (provisional_) {
    provisional_ = false;
    if (equals_newest(start)) return false;
    drop_newest();
  }
  if (count_ > 0 && equals_newest(start)) return false;
  // Pressures of the same instant as the newest entry, changed by the caller, or of no solve on
  // this system: the trend of the kept ones no longer leads to them.
  clear();
  int local = 1, zero = 0;
#pragma omp parallel for schedule(static) reduction(min : local) if (on_team())
  for (int i = 0; i < n_; ++i) local = std::min(local, start[i] == 0 ? 1 : 0);
  MPI_Allreduce(&local, &zero, 1, MPI_INT, MPI_MIN, comm_);
  return zero == 0;
}

void SolutionHistory::add(const double* x, const double* gx, double step) {
  if (capacity() == 0) return;
  const double t = count_ > 0 ? time_[head_] : 0;
  head_ = (head_ + 1) % capacity();
  time_[head_] = t;
  step_[head_] = step;
  count_ = std::min(count_ + 1, capacity());
  std::copy(x, x + n_, x_[head_].begin());
  std::copy(gx, gx + n_, gx_[head_].begin());
  provisional_ = false;
}

void SolutionHistory::add_provisional(const double* x, const double* b, const double* r, double step) {
  if (capacity() == 0) return;
  int local = 1, finite = 0;
#pragma omp parallel for schedule(static) reduction(min : local) if (on_team())
  for (int i = 0; i < n_; ++i) local = std::min(local, std::isfinite(x[i]) && std::isfinite(b[i] - r[i]) ? 1 : 0);
  MPI_Allreduce(&local, &finite, 1, MPI_INT, MPI_MIN, comm_);
  if (!finite) {
    clear();
    return;
  }
  const double t = count_ > 0 ? time_[head_] + step : 0;
  head_ = (head_ + 1) % capacity();
  time_[head_] = t;
  step_[head_] = step;
  count_ = std::min(count_ + 1, capacity());
  double* keep = x_[head_].data();
  double* product = gx_[head_].data();
#pragma omp parallel for schedule(static) if (on_team())
  for (int i = 0; i < n_; ++i) {
    keep[i] = x[i];
    product[i] = b[i] - r[i];
  }
  provisional_ = true;
}

int SolutionHistory::predict(const double* b, double* x, double step) {
  const int k = count_;
  if (k == 0) return -1;
  std::array<const double*, kMax> xs{}, gs{};
  std::array<double, kMax> t{};
  for (int j = 0; j < k; ++j) {
    const int slot = (head_ + capacity() - j) % capacity();
    xs[j] = x_[slot].data();
    gs[j] = gx_[slot].data();
    t[j] = time_[slot] - 0.5 * step_[slot];
  }
  // The orders whose nodes are distinct (a time step of zero repeats an instant).
  int orders = 1;
  while (orders < k && t[orders] < t[orders - 1]) ++orders;
  std::array<std::array<double, kMax>, kMax> w{};
  const double target = time_[head_] + 0.5 * step;
  for (int order = 0; order < orders; ++order) w[order] = lagrange(t, order, target);
  // One pass for the residual b - G x of each extrapolation, entry by entry (b and G x agree to
  // many digits: a difference of norms would lose them).
  std::array<std::array<double, kMax>, kSumChunks> part{};  // the residuals' sums by fixed chunks
#pragma omp parallel for schedule(static) if (on_team())
  for (int c = 0; c < kSumChunks; ++c)
    for (int i = chunk_begin(n_, c); i < chunk_begin(n_, c + 1); ++i)
      for (int order = 0; order < orders; ++order) {
        double r = b[i];
        for (int j = 0; j <= order; ++j) r -= w[order][j] * gs[j][i];
        part[c][order] += r * r;
      }
  std::array<double, kMax> local{}, global{};
  for (const auto& p : part)
    for (int order = 0; order < orders; ++order) local[order] += p[order];
  MPI_Allreduce(local.data(), global.data(), orders, MPI_DOUBLE, MPI_SUM, comm_);
  int best = 0;
  for (int order = 1; order < orders; ++order)
    if (global[order] < global[best]) best = order;
  if (!std::isfinite(global[best])) {
    clear();
    return -1;
  }
#pragma omp parallel for schedule(static) if (on_team())
  for (int i = 0; i < n_; ++i) {
    double v = 0;
    for (int j = 0; j <= best; ++j) v += w[best][j] * xs[j][i];
    x[i] = v;
  }
  return best;
}

}  // namespace pfv
