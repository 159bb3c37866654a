// Forward and back substitution with a supernodal Cholesky factor on several threads.
//
// Disjoint subtrees of the supernodal elimination tree only write their own rows and those of
// their common ancestors (the "top"). The plan cuts the tree into one group of subtrees per
// thread, balanced by the number of factor entries, and a top solved on one thread: forwards
// the groups run in parallel (updates to top rows go to per-thread buffers, summed after),
// then the top; backwards the top first, then the groups in parallel. The solve is bound by
// reading the factor, so a second core adds memory bandwidth, and a float factor halves it.
#pragma once
#include <algorithm>
#include <utility>
#include <vector>

namespace pfv {

// A read-only view of a supernodal LL' factor with CHOLMOD's pattern (cholmod_factor: super,
// pi, s, Perm) and compacted values: supernode s (columns super[s]..super[s+1]-1, rows
// rows[pi[s]..pi[s+1]-1], nsrow of them) starts at values[start[s]], column by column, column j
// holding only its rows j..nsrow-1 (the lower trapezoid). The values are doubles or floats
// (exactly one is set): the substitution reads every entry once per pass, so floats halve its
// memory traffic.
struct SupernodalFactor {
  int n = 0, nsuper = 0;
  const int* super = nullptr;
  const int* pi = nullptr;
  const long* start = nullptr;
  const int* rows = nullptr;
  const int* perm = nullptr;
  const double* values = nullptr;
  const float* values32 = nullptr;
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
  // x = (L L')^-1 applied to b in the original ordering. With parallel = false the groups
  // and the shared supernodes' pieces run one after the other on the calling thread (same
  // arithmetic, the same result to the bit).
  void solve(const double* b, double* x, bool parallel = true);

 private:
  // Per-thread update buffers and the permuted right-hand side, in the factor's precision:
  // with a float factor the whole substitution runs in float (refinement recovers double
  // accuracy, and float arithmetic moves twice as many entries per vector instruction).
  template <class Real>
  struct Workspace {
    std::vector<std::vector<Real>> acc, work;
    std::vector<Real> y;
  };
  // Supernode s: its first column k1, its nscol columns and nsrow rows, the rows below its
  // diagonal block, and its values.
  template <class Real>
  struct Block {
    int k1, nscol, nsrow;
    const int* rows;
    const Real* L;
  };
  template <class Real>
  Block<Real> block(const Real* values, int s) const {
    const int k1 = L_.super[s];
    return {k1, L_.super[s + 1] - k1, L_.pi[s + 1] - L_.pi[s], L_.rows + L_.pi[s] + (L_.super[s + 1] - k1),
            values + L_.start[s]};
  }
  template <class Real>
  void forward(const Real* values, Workspace<Real>& ws, int s, Real* acc, Real* w);
  template <class Real>
  void backward(const Real* values, Workspace<Real>& ws, int s, Real* w);
  // Thread t of nt's part of supernode s (a top one, after all of its descendants).
  template <class Real>
  void forward_shared(const Real* values, Workspace<Real>& ws, int s, int t, int nt);
  template <class Real>
  void backward_shared(const Real* values, Workspace<Real>& ws, int s, int t, int nt);
  template <class Real>
  void solve_with(const Real* values, Workspace<Real>& ws, const double* b, double* x, bool parallel);

  SupernodalFactor L_;
  std::vector<std::vector<std::pair<int, int>>> groups_;  // per thread: supernode ranges
  std::vector<int> top_;                                  // top supernodes, increasing
  std::vector<char> shared_;                              // per top_ entry
  std::vector<char> top_row_;                             // per row: owned by a top supernode
  std::vector<int> top_rows_;
  Workspace<double> ws64_;
  Workspace<float> ws32_;
  double top_fraction_ = 1;
};

}  // namespace pfv
