// Forward and back substitution with a supernodal Cholesky factor on several threads.
//
// Disjoint subtrees of the supernodal elimination tree only write their own rows and those of
// their common ancestors (the "top"). The plan cuts the tree into one group of subtrees per
// thread, balanced by the number of factor entries, and a top solved on one thread: forwards
// the groups run in parallel (updates to top rows go to per-thread buffers, summed after),
// then the top; backwards the top first, then the groups in parallel. The solve is bound by
// reading the factor, so a second core adds memory bandwidth, and a 32-bit factor halves it.
#pragma once
#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "pfv/common/schedule_choice.hpp"

namespace pfv {

// A read-only view of a supernodal LL' factor with CHOLMOD's pattern (cholmod_factor: super,
// pi, s, Perm) and compacted values: supernode s (columns super[s]..super[s+1]-1, rows
// rows[pi[s]..pi[s+1]-1], nsrow of them) starts at values[start[s]], column by column, column j
// holding only its rows j..nsrow-1 (the lower trapezoid). The values are doubles, or 32-bit
// integers q with L(i, j) ~ q(i, j) * scale[j] for the column's scale (exactly one of values and
// scaled is set): the substitution reads every entry once per pass, so 32-bit entries halve
// its memory traffic. The arithmetic is double either way.
struct SupernodalFactor {
  int n = 0, nsuper = 0;
  const int* super = nullptr;
  const int* pi = nullptr;
  const long* start = nullptr;
  const int* rows = nullptr;
  const int* perm = nullptr;
  const double* values = nullptr;
  const std::int32_t* scaled = nullptr;
  const double* scale = nullptr;  // per column, in elimination order; with 'scaled'
};

class ParallelSubstitution {
 public:
  void plan(const SupernodalFactor& factor, int threads);
  int threads() const { return static_cast<int>(groups_.size()); }
  double top_fraction() const { return top_fraction_; }  // share of entries in the top
  // Top supernodes large enough to be shared between the threads, by rows (forward) and by
  // columns (backward) of blocks of kSharedBlock columns. The top is mostly the last
  // separators: at 10 000 spheres one dense block of 1 200 columns, 12 % of the entries.
  int shared_top_supernodes() const { return static_cast<int>(std::count(shared_.begin(), shared_.end(), 1)); }
  static constexpr long kMinSharedEntries = 1 << 16;
  static constexpr int kSharedBlock = 64;
  // Every other supernode is solved by blocks of kColumnBlock columns: the block's small
  // triangle, then its columns against all the rows below it in one sweep (forwards, four
  // columns per sweep) or in four dots sharing one pass over the known rows (backwards). The
  // chain of dependent operations, from one column's value to the next, is then a block's
  // triangle and a multiplication by the reciprocal of the diagonal, precomputed per factor.
  // Column by column, every column would wait for a division and a dot's reduction, and that
  // latency, not the reading of the factor, would bound the narrow supernodes that hold most
  // of the entries.
  static constexpr int kColumnBlock = 4;
  // x = (L L')^-1 applied to b in the original ordering. With parallel = false the groups
  // and the shared supernodes' pieces run one after the other on the calling thread (same
  // arithmetic, the same result to the bit). With parallel = true it runs one of three
  // schedules, all giving that result: serial; the groups on the team and the top on the
  // calling thread (a fork and a join per sweep); or that and the shared supernodes on the
  // team too (a barrier per block of kSharedBlock columns, about a hundred per solve at 10 000
  // spheres). On free cores sharing pays; on cores other processes hold, each barrier waits up
  // to a time slice for a descheduled thread, and the shared schedule is then the slowest by
  // far. So the schedule is the fastest measured on this factor's solves
  // (schedule_choice.hpp); the plan is the same whichever runs.
  void solve(const double* b, double* x, bool parallel = true);
  enum class Schedule { kSerial, kGroups, kSharedTop };
  Schedule last_schedule() const { return last_schedule_; }

 private:
  // Supernode s: its first column k1, its nscol columns and nsrow rows, the rows below its
  // diagonal block, its values and (32-bit entries) its columns' scales.
  template <class Stored>
  struct Block {
    int k1, nscol, nsrow;
    const int* rows;
    const Stored* L;
    const double* scale;
  };
  template <class Stored>
  Block<Stored> block(const Stored* values, int s) const {
    const int k1 = L_.super[s];
    return {k1,
            L_.super[s + 1] - k1,
            L_.pi[s + 1] - L_.pi[s],
            L_.rows + L_.pi[s] + (L_.super[s + 1] - k1),
            values + L_.start[s],
            L_.scale ? L_.scale + k1 : nullptr};
  }
  // 'thread' is the group (forward, backward) or the thread of the team (shared supernodes);
  // its buffers are acc_[thread], work_[thread] and scaled_[thread].
  template <class Stored>
  void forward(const Stored* values, int s, int thread, bool top);
  template <class Stored>
  void backward(const Stored* values, int s, int thread);
  // Thread t of nt's part of supernode s (a top one, after all of its descendants).
  template <class Stored>
  void forward_shared(const Stored* values, int s, int t, int nt);
  template <class Stored>
  void backward_shared(const Stored* values, int s, int t, int nt);
  template <class Stored>
  void solve_with(const Stored* values, const double* b, double* x, Schedule schedule);

  SupernodalFactor L_;
  std::vector<std::vector<std::pair<int, int>>> groups_;  // per thread: supernode ranges
  std::vector<int> top_;                                  // top supernodes, increasing
  std::vector<char> shared_;                              // per top_ entry
  std::vector<char> top_row_;                             // per row: owned by a top supernode
  std::vector<int> top_rows_;
  // Per group: updates of top rows, the rows below a supernode, and x(j) * scale(j) of its
  // columns (32-bit entries); the permuted right-hand side and solution.
  std::vector<std::vector<double>> acc_, work_, scaled_;
  std::vector<double> y_;
  std::vector<double> inverse_;  // per column, in elimination order: 1 / L(j, j), set by plan()
  double top_fraction_ = 1;
  ScheduleChoice<3> choice_;  // indexed by Schedule
  Schedule last_schedule_ = Schedule::kSerial;
};

}  // namespace pfv
