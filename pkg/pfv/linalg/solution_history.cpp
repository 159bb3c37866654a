#include "pfv/linalg/solution_history.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace pfv {
namespace {

constexpr int kMax = 4;  // entries the per-row difference tables below hold

// Backward differences of v[0] (newest) ... v[k-1], in place: v[l] becomes the l-th difference
// at the newest entry.
inline void newton(std::array<double, kMax>& v, int k) {
  for (int l = 1; l < k; ++l)
    for (int j = k - 1; j >= l; --j) v[j] = v[j - 1] - v[j];
}

}  // namespace

SolutionHistory::SolutionHistory(MPI_Comm comm, int n, int capacity) : comm_(comm), n_(n) {
  if (capacity < 0 || capacity > kMax) throw std::invalid_argument("a solution history keeps 0 to 4 solutions");
  x_.assign(capacity, std::vector<double>(n));
  gx_.assign(capacity, std::vector<double>(n));
}

bool SolutionHistory::equals_newest(const double* v) const {
  const std::vector<double>& x = newest();
  int local = std::equal(x.begin(), x.end(), v) ? 1 : 0, global = 0;
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
  int local = std::all_of(start, start + n_, [](double v) { return v == 0; }) ? 1 : 0, zero = 0;
  MPI_Allreduce(&local, &zero, 1, MPI_INT, MPI_MIN, comm_);
  return zero == 0;
}

void SolutionHistory::add(const double* x, const double* gx) {
  if (capacity() == 0) return;
  head_ = (head_ + 1) % capacity();
  count_ = std::min(count_ + 1, capacity());
  std::copy(x, x + n_, x_[head_].begin());
  std::copy(gx, gx + n_, gx_[head_].begin());
  provisional_ = false;
}

void SolutionHistory::add_provisional(const double* x, const double* b, const double* r) {
  if (capacity() == 0) return;
  int local = 1, finite = 0;
  for (int i = 0; i < n_ && local; ++i) local = std::isfinite(x[i]) && std::isfinite(b[i] - r[i]);
  MPI_Allreduce(&local, &finite, 1, MPI_INT, MPI_MIN, comm_);
  if (!finite) {
    clear();
    return;
  }
  head_ = (head_ + 1) % capacity();
  count_ = std::min(count_ + 1, capacity());
  std::vector<double>& keep = x_[head_];
  std::vector<double>& product = gx_[head_];
  for (int i = 0; i < n_; ++i) {
    keep[i] = x[i];
    product[i] = b[i] - r[i];
  }
  provisional_ = true;
}

int SolutionHistory::predict(const double* b, double* x) {
  const int k = count_;
  if (k == 0) return -1;
  std::array<const double*, kMax> xs{}, gs{};
  for (int j = 0; j < k; ++j) {
    const int slot = (head_ + capacity() - j) % capacity();
    xs[j] = x_[slot].data();
    gs[j] = gx_[slot].data();
  }
  // One pass for the residual b - G x of each extrapolation, entry by entry (b and G x agree to
  // many digits: a difference of norms would lose them).
  std::array<double, kMax> local{}, global{};
  for (int i = 0; i < n_; ++i) {
    std::array<double, kMax> gd{};
    for (int j = 0; j < k; ++j) gd[j] = gs[j][i];
    newton(gd, k);
    double r = b[i];
    for (int order = 0; order < k; ++order) {
      r -= gd[order];
      local[order] += r * r;
    }
  }
  MPI_Allreduce(local.data(), global.data(), k, MPI_DOUBLE, MPI_SUM, comm_);
  int best = 0;
  for (int order = 1; order < k; ++order)
    if (global[order] < global[best]) best = order;
  if (!std::isfinite(global[best])) {
    clear();
    return -1;
  }
  for (int i = 0; i < n_; ++i) {
    std::array<double, kMax> d{};
    for (int j = 0; j <= best; ++j) d[j] = xs[j][i];
    newton(d, best + 1);
    double v = 0;
    for (int order = 0; order <= best; ++order) v += d[order];
    x[i] = v;
  }
  return best;
}

}  // namespace pfv
