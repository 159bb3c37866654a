#include "parallel_substitution.hpp"

#include <algorithm>
#include <numeric>
#ifdef _OPENMP
#include <omp.h>
#endif

namespace pfv {
namespace {

// Dot product with eight partial sums (vectorises without -ffast-math).
template <class Real>
inline Real dot(const Real* a, const Real* b, int n) {
  Real s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int i = 0;
  for (; i + 8 <= n; i += 8)
    for (int k = 0; k < 8; ++k) s[k] += a[i + k] * b[i + k];
  for (; i < n; ++i) s[0] += a[i] * b[i];
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// Column j of a trapezoid block of nsrow rows, indexed by row (entries j..nsrow-1 exist).
template <class Real>
inline const Real* trapezoid_column(const Real* block, std::ptrdiff_t nsrow, std::ptrdiff_t j) {
  return block + j * nsrow - j * (j + 1) / 2;
}

// u[i] -= sum over columns j in [j0, j1) of L(row0 + i, j) x[j], for i < count, four columns
// per sweep over u: with one column per sweep the loads and stores of u, not the factor,
// bound the narrow supernodes. The rows row0.. must lie below column j1 - 1's diagonal.
template <class Real>
inline void subtract_columns(const Real* block, int nsrow, int j0, int j1, const Real* x, int row0, Real* u,
                             int count) {
  int j = j0;
  for (; j + 4 <= j1; j += 4) {
    const Real* c0 = trapezoid_column(block, nsrow, j) + row0;
    const Real* c1 = trapezoid_column(block, nsrow, j + 1) + row0;
    const Real* c2 = trapezoid_column(block, nsrow, j + 2) + row0;
    const Real* c3 = trapezoid_column(block, nsrow, j + 3) + row0;
    const Real x0 = x[j], x1 = x[j + 1], x2 = x[j + 2], x3 = x[j + 3];
    for (int i = 0; i < count; ++i) u[i] -= (c0[i] * x0 + c1[i] * x1) + (c2[i] * x2 + c3[i] * x3);
  }
  for (; j < j1; ++j) {
    const Real* col = trapezoid_column(block, nsrow, j) + row0;
    const Real xj = x[j];
    for (int i = 0; i < count; ++i) u[i] -= col[i] * xj;
  }
}

// The forward sweep reads the factor as one ascending stream, but in short pieces (most
// supernodes are a few hundred bytes): the hardware prefetcher restarts on each, and the sweep
// waits for memory. Asking for the bytes kPrefetchAhead ahead of the block being read keeps
// the stream going (development measurement, 10 000 spheres, factor out of cache: forward
// sweep 5.4 -> 4.0 ms in float, 7.1 -> 5.7 ms in double, together with the four-column
// rectangle; doc/benchmarks.md has the project scripts' numbers). The backward sweep gained
// nothing from the same (tried).
constexpr std::ptrdiff_t kPrefetchAhead = 2048;

template <class Real>
inline void prefetch_ahead(const Real* block, const Real* block_end, const Real* values_end) {
  const char* a = reinterpret_cast<const char*>(block);
  const char* z = reinterpret_cast<const char*>(block_end);
  const char* end = reinterpret_cast<const char*>(values_end);
  if (end - z <= kPrefetchAhead) return;  // the end of the stream: nothing to ask for
  for (a += kPrefetchAhead, z += kPrefetchAhead; a < z; a += 64) __builtin_prefetch(a);
}

inline int thread_index() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}

inline int omp_team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

}  // namespace

void ParallelSubstitution::plan(const SupernodalFactor& f, int threads) {
  L_ = f;
  const int ns = f.nsuper;
  std::vector<int> super_of(f.n);
  for (int s = 0; s < ns; ++s)
    for (int k = f.super[s]; k < f.super[s + 1]; ++k) super_of[k] = s;
  std::vector<int> parent(ns, -1), first(ns);
  std::vector<double> work(ns), subtree(ns);
  std::vector<std::vector<int>> children(ns);
  std::vector<int> roots;
  std::size_t max_rows = 0;
  for (int s = 0; s < ns; ++s) {
    const int nscol = f.super[s + 1] - f.super[s], nsrow = f.pi[s + 1] - f.pi[s];
    max_rows = std::max<std::size_t>(max_rows, nsrow);
    work[s] = nscol * (nsrow - 0.5 * nscol);
    if (nsrow > nscol) {
      parent[s] = super_of[f.rows[f.pi[s] + nscol]];
      children[parent[s]].push_back(s);
    } else {
      roots.push_back(s);
    }
  }
  // Supernodes are postordered (children first), so subtrees are contiguous ranges.
  for (int s = 0; s < ns; ++s) {
    first[s] = s;
    subtree[s] = work[s];
  }
  for (int s = 0; s < ns; ++s)
    for (int c : children[s]) {
      first[s] = std::min(first[s], first[c]);
      subtree[s] += subtree[c];
    }
  const double total = std::accumulate(work.begin(), work.end(), 0.0);

  // Split the heaviest open subtree until the groups balance (longest-processing-time).
  std::vector<int> open = roots;
  std::vector<char> is_top(ns, 0);
  double top_work = 0;
  std::vector<std::vector<int>> best_groups;
  double best_time = total;  // time of the serial solve, in entries
  for (int iteration = 0; iteration < ns && threads > 1; ++iteration) {
    std::sort(open.begin(), open.end(), [&](int a, int b) { return subtree[a] > subtree[b]; });
    std::vector<std::vector<int>> groups(threads);
    std::vector<double> load(threads, 0.0);
    for (int r : open) {
      const int t = static_cast<int>(std::min_element(load.begin(), load.end()) - load.begin());
      groups[t].push_back(r);
      load[t] += subtree[r];
    }
    const double time = top_work + *std::max_element(load.begin(), load.end());
    if (time < best_time) {
      best_time = time;
      best_groups = groups;
    }
    if (open.empty() || top_work > 0.5 * total) break;
    const int heaviest = open.front();
    open.erase(open.begin());
    is_top[heaviest] = 1;
    top_work += work[heaviest];
    open.insert(open.end(), children[heaviest].begin(), children[heaviest].end());
  }

  groups_.clear();
  top_.clear();
  std::vector<char> in_group(ns, 0);
  for (const auto& g : best_groups) {
    groups_.emplace_back();
    for (int r : g) {
      groups_.back().emplace_back(first[r], r);
      for (int s = first[r]; s <= r; ++s) in_group[s] = 1;
    }
    std::sort(groups_.back().begin(), groups_.back().end());
  }
  if (groups_.empty()) groups_.emplace_back();  // one thread: everything is "top"
  for (int s = 0; s < ns; ++s)
    if (!in_group[s]) top_.push_back(s);
  top_row_.assign(f.n, 0);
  top_rows_.clear();
  double top_entries = 0;
  for (int s : top_) {
    top_entries += work[s];
    for (int k = f.super[s]; k < f.super[s + 1]; ++k) {
      top_row_[k] = 1;
      top_rows_.push_back(k);
    }
  }
  top_fraction_ = total > 0 ? top_entries / total : 1;
  shared_.clear();
  for (int s : top_) shared_.push_back(threads > 1 && f.start[s + 1] - f.start[s] >= kMinSharedEntries);
  const auto size = [&](auto& ws) {
    ws.acc.assign(groups_.size(), {});
    ws.work.assign(groups_.size(), {});
    for (std::size_t t = 0; t < groups_.size(); ++t) {
      ws.acc[t].assign(f.n, 0);
      ws.work[t].assign(max_rows, 0);
    }
    ws.y.assign(f.n, 0);
  };
  ws64_ = {};
  ws32_ = {};
  if (f.values32)
    size(ws32_);
  else
    size(ws64_);
}

template <class Real>
void ParallelSubstitution::forward(const Real* values, Workspace<Real>& ws, int s, Real* acc, Real* w) {
  const Block<Real> b = block(values, s);
  const int nrest = b.nsrow - b.nscol;
  prefetch_ahead(b.L, values + L_.start[s + 1], values + L_.start[L_.nsuper]);
  Real* y = ws.y.data() + b.k1;  // this supernode's rows
  for (int j = 0; j < b.nscol; ++j) {  // the dense triangle
    const Real* col = trapezoid_column(b.L, b.nsrow, j);
    const Real xj = (y[j] /= col[j]);
    for (int i = j + 1; i < b.nscol; ++i) y[i] -= col[i] * xj;
  }
  // The rectangle below it: w = -L21 y1.
  std::fill(w, w + nrest, Real(0));
  subtract_columns(b.L, b.nsrow, 0, b.nscol, y, b.nscol, w, nrest);
  Real* all = ws.y.data();
  if (acc) {  // top rows are shared between threads: collect their updates apart
    for (int i = 0; i < nrest; ++i) {
      if (top_row_[b.rows[i]])
        acc[b.rows[i]] -= w[i];
      else
        all[b.rows[i]] += w[i];
    }
  } else {
    for (int i = 0; i < nrest; ++i) all[b.rows[i]] += w[i];
  }
}

template <class Real>
void ParallelSubstitution::backward(const Real* values, Workspace<Real>& ws, int s, Real* w) {
  const Block<Real> b = block(values, s);
  const int nrest = b.nsrow - b.nscol;
  Real* y = ws.y.data();
  for (int i = 0; i < nrest; ++i) w[i] = y[b.rows[i]];
  y += b.k1;
  for (int j = b.nscol - 1; j >= 0; --j) {
    const Real* col = trapezoid_column(b.L, b.nsrow, j);
    const Real t = y[j] - dot(col + b.nscol, w, nrest) - dot(col + j + 1, y + j + 1, b.nscol - j - 1);
    y[j] = t / col[j];
  }
}

namespace {

// The part [a, b) of the range [lo, hi) that thread t of nt takes.
inline std::pair<int, int> share(int lo, int hi, int t, int nt) {
  const long n = hi - lo;
  return {lo + static_cast<int>(n * t / nt), lo + static_cast<int>(n * (t + 1) / nt)};
}

inline void barrier() {
#pragma omp barrier
}

}  // namespace

// The supernode's rows in one vector u (its own columns, then the rows below), solved by
// blocks of kSharedBlock columns: the small triangle of a block on thread 0, then the update
// of all rows below the block split between the threads. Every row sees the same operations
// in the same order whatever nt is.
template <class Real>
void ParallelSubstitution::forward_shared(const Real* values, Workspace<Real>& ws, int s, int t, int nt) {
  const Block<Real> b = block(values, s);
  Real* y = ws.y.data();
  Real* u = ws.work[0].data();
  {
    const auto [lo, hi] = share(0, b.nsrow, t, nt);
    for (int i = lo; i < hi; ++i) u[i] = i < b.nscol ? y[b.k1 + i] : Real(0);
  }
  barrier();
  for (int j0 = 0; j0 < b.nscol; j0 += kSharedBlock) {
    const int j1 = std::min(j0 + kSharedBlock, b.nscol);
    if (t == 0)
      for (int j = j0; j < j1; ++j) {
        const Real* col = trapezoid_column(b.L, b.nsrow, j);
        const Real xj = (u[j] /= col[j]);
        for (int i = j + 1; i < j1; ++i) u[i] -= col[i] * xj;
      }
    barrier();
    const auto [lo, hi] = share(j1, b.nsrow, t, nt);
    subtract_columns(b.L, b.nsrow, j0, j1, u, lo, u + lo, hi - lo);
    barrier();
  }
  const auto [lo, hi] = share(0, b.nsrow, t, nt);
  for (int i = lo; i < hi; ++i) {  // the rows below belong to no other supernode of the top phase
    if (i < b.nscol)
      y[b.k1 + i] = u[i];
    else
      y[b.rows[i - b.nscol]] += u[i];  // u holds minus the update
  }
  barrier();
}

// Blocks from the last: the dots of a block's columns with the rows below it, split between
// the threads by columns, then the block's triangle on thread 0.
template <class Real>
void ParallelSubstitution::backward_shared(const Real* values, Workspace<Real>& ws, int s, int t, int nt) {
  const Block<Real> b = block(values, s);
  Real* y = ws.y.data();
  Real* u = ws.work[0].data();
  {
    const auto [lo, hi] = share(0, b.nsrow, t, nt);
    for (int i = lo; i < hi; ++i) u[i] = i < b.nscol ? y[b.k1 + i] : y[b.rows[i - b.nscol]];
  }
  barrier();
  for (int j1 = b.nscol; j1 > 0;) {
    const int j0 = std::max(0, j1 - kSharedBlock);
    const auto [lo, hi] = share(j0, j1, t, nt);
    for (int j = lo; j < hi; ++j) u[j] -= dot(trapezoid_column(b.L, b.nsrow, j) + j1, u + j1, b.nsrow - j1);
    barrier();
    if (t == 0)
      for (int j = j1 - 1; j >= j0; --j) {
        const Real* col = trapezoid_column(b.L, b.nsrow, j);
        u[j] = (u[j] - dot(col + j + 1, u + j + 1, j1 - j - 1)) / col[j];
      }
    barrier();
    j1 = j0;
  }
  const auto [lo, hi] = share(0, b.nscol, t, nt);
  for (int i = lo; i < hi; ++i) y[b.k1 + i] = u[i];
  barrier();
}

void ParallelSubstitution::solve(const double* b, double* x, bool parallel) {
  if (L_.values32)
    solve_with(L_.values32, ws32_, b, x, parallel);
  else
    solve_with(L_.values, ws64_, b, x, parallel);
}

template <class Real>
void ParallelSubstitution::solve_with(const Real* values, Workspace<Real>& ws, const double* b, double* x,
                                      bool parallel) {
  const int n = L_.n;
  for (int k = 0; k < n; ++k) ws.y[k] = static_cast<Real>(b[L_.perm[k]]);
  const int groups = static_cast<int>(groups_.size());
  parallel = parallel && groups > 1;
  const auto forward_group = [&](int t) {
    for (const auto& [a, z] : groups_[t])
      for (int s = a; s <= z; ++s) forward(values, ws, s, ws.acc[t].data(), ws.work[t].data());
  };
  const auto backward_group = [&](int t) {
    for (auto g = groups_[t].rbegin(); g != groups_[t].rend(); ++g)
      for (int s = g->second; s >= g->first; --s) backward(values, ws, s, ws.work[t].data());
  };
  // A team smaller than asked for (a thread limit, a nested region) still covers every group.
  if (parallel) {
#pragma omp parallel num_threads(groups)
    for (int g = thread_index(); g < groups; g += omp_team_size()) forward_group(g);
  } else {
    for (int t = 0; t < groups; ++t) forward_group(t);
  }
  for (int k : top_rows_)
    for (int t = 0; t < groups; ++t) {
      ws.y[k] -= ws.acc[t][k];
      ws.acc[t][k] = 0;
    }
  // The top, on one thread except for the shared supernodes, whose pieces need all threads.
  const auto top = [&](int t, int nt) {
    const int nt_top = static_cast<int>(top_.size());
    for (int k = 0; k < nt_top; ++k) {
      if (shared_[k]) {
        forward_shared(values, ws, top_[k], t, nt);
      } else {
        if (t == 0) forward(values, ws, top_[k], static_cast<Real*>(nullptr), ws.work[0].data());
        barrier();
      }
    }
    for (int k = nt_top - 1; k >= 0; --k) {
      if (shared_[k]) {
        backward_shared(values, ws, top_[k], t, nt);
      } else {
        if (t == 0) backward(values, ws, top_[k], ws.work[0].data());
        barrier();
      }
    }
  };
  if (parallel && std::find(shared_.begin(), shared_.end(), 1) != shared_.end()) {
#pragma omp parallel num_threads(groups)
    top(thread_index(), omp_team_size());
  } else {
    top(0, 1);
  }
  if (parallel) {
#pragma omp parallel num_threads(groups)
    for (int g = thread_index(); g < groups; g += omp_team_size()) backward_group(g);
  } else {
    for (int t = 0; t < groups; ++t) backward_group(t);
  }
  for (int k = 0; k < n; ++k) x[L_.perm[k]] = ws.y[k];
}

}  // namespace pfv
