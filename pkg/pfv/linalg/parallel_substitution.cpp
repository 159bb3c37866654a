#include "pfv/linalg/parallel_substitution.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <numeric>
#include <type_traits>
#ifdef _OPENMP
#include <omp.h>
#endif

namespace pfv {
namespace {

// An entry as a double: 32-bit entries are converted here and scaled by their column's factor
// by the caller, once per column, not once per entry.
inline double value(double v) { return v; }
inline double value(std::int32_t v) { return static_cast<double>(v); }

// Dot product with eight partial sums (vectorises without -ffast-math).
template <class Stored>
inline double dot(const Stored* a, const double* b, int n) {
  double s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int i = 0;
  for (; i + 8 <= n; i += 8)
    for (int k = 0; k < 8; ++k) s[k] += value(a[i + k]) * b[i + k];
  for (; i < n; ++i) s[0] += value(a[i]) * b[i];
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// Column j of a trapezoid block of nsrow rows, indexed by row (entries j..nsrow-1 exist).
template <class Stored>
inline const Stored* trapezoid_column(const Stored* block, std::ptrdiff_t nsrow, std::ptrdiff_t j) {
  return block + j * nsrow - j * (j + 1) / 2;
}

// The scale of a block's column j: 1 for double entries (a constant the compiler folds).
template <class Stored>
inline double column_scale(const double* scale, int j) {
  if constexpr (std::is_same_v<Stored, double>)
    return 1.0;
  else
    return scale[j];
}

// u[i] -= sum over columns j in [j0, j1) of L(row0 + i, j) x[j], for i < count, four columns
// per sweep over u: with one column per sweep the loads and stores of u, not the factor,
// bound the narrow supernodes. The rows row0.. must lie below column j1 - 1's diagonal. x
// holds x(j) times column j's scale.
template <class Stored>
inline void subtract_columns(const Stored* block, int nsrow, int j0, int j1, const double* x, int row0, double* u,
                             int count) {
  int j = j0;
  for (; j + 4 <= j1; j += 4) {
    const Stored* c0 = trapezoid_column(block, nsrow, j) + row0;
    const Stored* c1 = trapezoid_column(block, nsrow, j + 1) + row0;
    const Stored* c2 = trapezoid_column(block, nsrow, j + 2) + row0;
    const Stored* c3 = trapezoid_column(block, nsrow, j + 3) + row0;
    const double x0 = x[j], x1 = x[j + 1], x2 = x[j + 2], x3 = x[j + 3];
    for (int i = 0; i < count; ++i)
      u[i] -= (value(c0[i]) * x0 + value(c1[i]) * x1) + (value(c2[i]) * x2 + value(c3[i]) * x3);
  }
  for (; j < j1; ++j) {
    const Stored* col = trapezoid_column(block, nsrow, j) + row0;
    const double xj = x[j];
    for (int i = 0; i < count; ++i) u[i] -= value(col[i]) * xj;
  }
}

// Columns [j0, j1) of the block's dense triangle, forwards, on u (the block's rows, from row
// 0): u(j) times the reciprocal of L(j, j) ('inverse', indexed like the columns), then the
// rows j+1..j1-1 below it. Leaves u(j) * scale(j) in x.
template <class Stored>
inline void solve_triangle(const Stored* block, const double* scale, const double* inverse, int nsrow, int j0, int j1,
                           double* u, double* x) {
  for (int j = j0; j < j1; ++j) {
    const Stored* col = trapezoid_column(block, nsrow, j);
    const double xj = (u[j] *= inverse[j]) * column_scale<Stored>(scale, j);
    x[j] = xj;
    for (int i = j + 1; i < j1; ++i) u[i] -= value(col[i]) * xj;
  }
}

// Four consecutive entries as doubles (GCC/Clang vector extensions: AVX where the kernels are
// built for it, pairs of SSE registers otherwise). dot4 is written with them because GCC
// vectorises its plain-array form by shuffling the four accumulators through the stack.
using Double4 = double __attribute__((vector_size(32)));
using Int4 = std::int32_t __attribute__((vector_size(16)));
inline Double4 load4(const double* p) {
  Double4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline Double4 load4(const std::int32_t* p) {
  Int4 v;
  std::memcpy(&v, p, sizeof v);
  return __builtin_convertvector(v, Double4);
}

// sum[c] = sum over i < count of column c's entry i times u[i], for the four columns c0..c3:
// one pass over u for the four, each with its own accumulator.
template <class Stored>
inline void dot4(const Stored* c0, const Stored* c1, const Stored* c2, const Stored* c3, const double* u, int count,
                 double sum[4]) {
  Double4 a0 = {0, 0, 0, 0}, a1 = a0, a2 = a0, a3 = a0;
  int i = 0;
  for (; i + 4 <= count; i += 4) {
    const Double4 v = load4(u + i);
    a0 += load4(c0 + i) * v;
    a1 += load4(c1 + i) * v;
    a2 += load4(c2 + i) * v;
    a3 += load4(c3 + i) * v;
  }
  sum[0] = (a0[0] + a0[1]) + (a0[2] + a0[3]);
  sum[1] = (a1[0] + a1[1]) + (a1[2] + a1[3]);
  sum[2] = (a2[0] + a2[1]) + (a2[2] + a2[3]);
  sum[3] = (a3[0] + a3[1]) + (a3[2] + a3[3]);
  for (; i < count; ++i) {
    const double v = u[i];
    sum[0] += value(c0[i]) * v;
    sum[1] += value(c1[i]) * v;
    sum[2] += value(c2[i]) * v;
    sum[3] += value(c3[i]) * v;
  }
}

// Each sweep reads the factor as one stream (forwards ascending, backwards descending), but
// in short pieces (most supernodes are a few hundred bytes): the hardware prefetcher restarts
// on each, and the sweep waits for memory. Asking for the bytes kPrefetchAhead beyond the
// block being read, in the sweep's direction, keeps the stream going; the gain hardly depends
// on the distance between 512 B and 16 KB (bench/solver_stages.py --sections=2).
constexpr std::ptrdiff_t kPrefetchAhead = 2048;

template <class Stored>
inline void prefetch_ahead(const Stored* block, const Stored* block_end, const Stored* values_end) {
  const char* a = reinterpret_cast<const char*>(block);
  const char* z = reinterpret_cast<const char*>(block_end);
  const char* end = reinterpret_cast<const char*>(values_end);
  if (end - z <= kPrefetchAhead) return;  // the end of the stream: nothing to ask for
  for (a += kPrefetchAhead, z += kPrefetchAhead; a < z; a += 64) __builtin_prefetch(a);
}

// The mirror image for the backward sweep: the block's byte range moved kPrefetchAhead down.
template <class Stored>
inline void prefetch_behind(const Stored* block, const Stored* block_end, const Stored* values_begin) {
  const char* a = reinterpret_cast<const char*>(block);
  const char* z = reinterpret_cast<const char*>(block_end);
  const char* begin = reinterpret_cast<const char*>(values_begin);
  if (a - begin <= kPrefetchAhead) return;  // the end of the stream
  for (a -= kPrefetchAhead, z -= kPrefetchAhead; a < z; a += 64) __builtin_prefetch(a);
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
  choice_.reset();  // another factor: other times
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
  const std::size_t buffers = std::max<std::size_t>(groups_.size(), threads);
  acc_.assign(buffers, std::vector<double>(f.n, 0.0));
  work_.assign(buffers, std::vector<double>(max_rows, 0.0));
  scaled_.assign(f.scaled ? buffers : 0, std::vector<double>(max_rows, 0.0));
  y_.assign(f.n, 0.0);
  inverse_.resize(f.n);
  for (int s = 0; s < ns; ++s) {
    const int nsrow = f.pi[s + 1] - f.pi[s];
    for (int j = 0; j < f.super[s + 1] - f.super[s]; ++j) {
      const int k = f.super[s] + j;
      const double diagonal = f.scaled ? trapezoid_column(f.scaled + f.start[s], nsrow, j)[j] * f.scale[k]
                                       : trapezoid_column(f.values + f.start[s], nsrow, j)[j];
      inverse_[k] = 1.0 / diagonal;
    }
  }
}

template <class Stored>
void ParallelSubstitution::forward(const Stored* values, int s, int thread, bool top) {
  const Block<Stored> b = block(values, s);
  prefetch_ahead(b.L, values + L_.start[s + 1], values + L_.start[L_.nsuper]);
  double* y = y_.data();
  double* u = work_[thread].data();  // its own rows, then minus the updates of the rows below
  double* x = u;                     // y(j) * scale(j), the same as u for double entries
  if constexpr (!std::is_same_v<Stored, double>) x = scaled_[thread].data();
  std::copy(y + b.k1, y + b.k1 + b.nscol, u);
  std::fill(u + b.nscol, u + b.nsrow, 0.0);
  const double* inverse = inverse_.data() + b.k1;
  for (int j0 = 0; j0 < b.nscol; j0 += kColumnBlock) {
    const int j1 = std::min(j0 + kColumnBlock, b.nscol);
    solve_triangle(b.L, b.scale, inverse, b.nsrow, j0, j1, u, x);
    subtract_columns(b.L, b.nsrow, j0, j1, x, j1, u + j1, b.nsrow - j1);
  }
  std::copy(u, u + b.nscol, y + b.k1);
  const double* w = u + b.nscol;
  const int nrest = b.nsrow - b.nscol;
  if (!top) {  // top rows are shared between threads: collect their updates apart
    double* acc = acc_[thread].data();
    for (int i = 0; i < nrest; ++i) {
      if (top_row_[b.rows[i]])
        acc[b.rows[i]] -= w[i];
      else
        y[b.rows[i]] += w[i];
    }
  } else {
    for (int i = 0; i < nrest; ++i) y[b.rows[i]] += w[i];
  }
}

template <class Stored>
void ParallelSubstitution::backward(const Stored* values, int s, int thread) {
  const Block<Stored> b = block(values, s);
  prefetch_behind(b.L, values + L_.start[s + 1], values);
  double* y = y_.data();
  double* u = work_[thread].data();  // its own rows, then the rows below
  std::copy(y + b.k1, y + b.k1 + b.nscol, u);
  for (int i = b.nscol; i < b.nsrow; ++i) u[i] = y[b.rows[i - b.nscol]];
  const double* inverse = inverse_.data() + b.k1;
  for (int j1 = b.nscol; j1 > 0;) {
    const int j0 = (j1 - 1) / kColumnBlock * kColumnBlock;  // the forward sweep's blocks
    // The block's columns against the rows below the block (all known), then its triangle.
    double below[kColumnBlock];
    const int count = b.nsrow - j1;
    static_assert(kColumnBlock == 4, "a whole block is one dot4");
    if (j1 - j0 == kColumnBlock) {
      dot4(trapezoid_column(b.L, b.nsrow, j0) + j1, trapezoid_column(b.L, b.nsrow, j0 + 1) + j1,
           trapezoid_column(b.L, b.nsrow, j0 + 2) + j1, trapezoid_column(b.L, b.nsrow, j0 + 3) + j1, u + j1, count,
           below);
    } else {
      for (int j = j0; j < j1; ++j) below[j - j0] = dot(trapezoid_column(b.L, b.nsrow, j) + j1, u + j1, count);
    }
    for (int j = j1 - 1; j >= j0; --j) {
      const Stored* col = trapezoid_column(b.L, b.nsrow, j);
      double d = below[j - j0];
      for (int i = j + 1; i < j1; ++i) d += value(col[i]) * u[i];
      u[j] = (u[j] - d * column_scale<Stored>(b.scale, j)) * inverse[j];
    }
    j1 = j0;
  }
  std::copy(u, u + b.nscol, y + b.k1);
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
template <class Stored>
void ParallelSubstitution::forward_shared(const Stored* values, int s, int t, int nt) {
  const Block<Stored> b = block(values, s);
  double* y = y_.data();
  double* u = work_[0].data();
  double* x = u;
  if constexpr (!std::is_same_v<Stored, double>) x = scaled_[0].data();
  {
    const auto [lo, hi] = share(0, b.nsrow, t, nt);
    for (int i = lo; i < hi; ++i) u[i] = i < b.nscol ? y[b.k1 + i] : 0.0;
  }
  barrier();
  for (int j0 = 0; j0 < b.nscol; j0 += kSharedBlock) {
    const int j1 = std::min(j0 + kSharedBlock, b.nscol);
    if (t == 0) solve_triangle(b.L, b.scale, inverse_.data() + b.k1, b.nsrow, j0, j1, u, x);
    barrier();
    const auto [lo, hi] = share(j1, b.nsrow, t, nt);
    subtract_columns(b.L, b.nsrow, j0, j1, x, lo, u + lo, hi - lo);
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
template <class Stored>
void ParallelSubstitution::backward_shared(const Stored* values, int s, int t, int nt) {
  const Block<Stored> b = block(values, s);
  double* y = y_.data();
  double* u = work_[0].data();
  {
    const auto [lo, hi] = share(0, b.nsrow, t, nt);
    for (int i = lo; i < hi; ++i) u[i] = i < b.nscol ? y[b.k1 + i] : y[b.rows[i - b.nscol]];
  }
  barrier();
  for (int j1 = b.nscol; j1 > 0;) {
    const int j0 = std::max(0, j1 - kSharedBlock);
    const auto [lo, hi] = share(j0, j1, t, nt);
    for (int j = lo; j < hi; ++j)
      u[j] -= dot(trapezoid_column(b.L, b.nsrow, j) + j1, u + j1, b.nsrow - j1) * column_scale<Stored>(b.scale, j);
    barrier();
    if (t == 0)
      for (int j = j1 - 1; j >= j0; --j) {
        const Stored* col = trapezoid_column(b.L, b.nsrow, j);
        const double sj = column_scale<Stored>(b.scale, j);
        u[j] = (u[j] - dot(col + j + 1, u + j + 1, j1 - j - 1) * sj) * inverse_[b.k1 + j];
      }
    barrier();
    j1 = j0;
  }
  const auto [lo, hi] = share(0, b.nscol, t, nt);
  for (int i = lo; i < hi; ++i) y[b.k1 + i] = u[i];
  barrier();
}

void ParallelSubstitution::solve(const double* b, double* x, bool parallel) {
  // The schedules on offer: serial, the groups on the team, and the shared top as well.
  const bool any_shared = std::find(shared_.begin(), shared_.end(), 1) != shared_.end();
  const int available = parallel && groups_.size() > 1 ? (any_shared ? 3 : 2) : 1;
  const Schedule schedule = available > 1 ? static_cast<Schedule>(choice_.pick(available)) : Schedule::kSerial;
  const auto start = std::chrono::steady_clock::now();
  if (L_.scaled)
    solve_with(L_.scaled, b, x, schedule);
  else
    solve_with(L_.values, b, x, schedule);
  if (available > 1)
    choice_.record(available, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  last_schedule_ = schedule;
}

template <class Stored>
void ParallelSubstitution::solve_with(const Stored* values, const double* b, double* x, Schedule schedule) {
  const int n = L_.n;
  for (int k = 0; k < n; ++k) y_[k] = b[L_.perm[k]];
  const int groups = static_cast<int>(groups_.size());
  const bool parallel = schedule != Schedule::kSerial;
  const auto forward_group = [&](int g) {
    for (const auto& [a, z] : groups_[g])
      for (int s = a; s <= z; ++s) forward(values, s, g, false);
  };
  const auto backward_group = [&](int g) {
    for (auto r = groups_[g].rbegin(); r != groups_[g].rend(); ++r)
      for (int s = r->second; s >= r->first; --s) backward(values, s, g);
  };
  // A team smaller than asked for (a thread limit, a nested region) still covers every group.
  if (parallel) {
#pragma omp parallel num_threads(groups)
    for (int g = thread_index(); g < groups; g += omp_team_size()) forward_group(g);
  } else {
    for (int g = 0; g < groups; ++g) forward_group(g);
  }
  for (int k : top_rows_)
    for (int g = 0; g < groups; ++g) {
      y_[k] -= acc_[g][k];
      acc_[g][k] = 0;
    }
  // The top, on one thread except for the shared supernodes, whose pieces need all threads.
  const auto top = [&](int t, int nt) {
    const int nt_top = static_cast<int>(top_.size());
    for (int k = 0; k < nt_top; ++k) {
      if (shared_[k]) {
        forward_shared(values, top_[k], t, nt);
      } else {
        if (t == 0) forward(values, top_[k], 0, true);
        barrier();
      }
    }
    for (int k = nt_top - 1; k >= 0; --k) {
      if (shared_[k]) {
        backward_shared(values, top_[k], t, nt);
      } else {
        if (t == 0) backward(values, top_[k], 0);
        barrier();
      }
    }
  };
  if (schedule == Schedule::kSharedTop) {
#pragma omp parallel num_threads(groups)
    top(thread_index(), omp_team_size());
  } else {
    top(0, 1);
  }
  if (parallel) {
#pragma omp parallel num_threads(groups)
    for (int g = thread_index(); g < groups; g += omp_team_size()) backward_group(g);
  } else {
    for (int g = 0; g < groups; ++g) backward_group(g);
  }
  for (int k = 0; k < n; ++k) x[L_.perm[k]] = y_[k];
}

}  // namespace pfv
