// Forward and back substitution with a supernodal Cholesky factor on several threads.
//
// Disjoint subtrees of the supernodal elimination tree only write their own rows and those of
// their common ancestors (the "top"). The plan cuts the tree into one group of subtrees per
// thread, balanced by the number of factor entries, and a top solved on one thread: forwards
// the groups run in parallel (updates to top rows go to per-thread buffers, summed after),
// then the top; backwards the top first, then the groups in parallel. The solve is bound by
// reading the factor, so a second core adds memory bandwidth.
#pragma once
#include <utility>
#include <vector>

namespace pfv {

// A read-only view of CHOLMOD's supernodal LL' factor (see cholmod_factor: super, pi, px, s).
struct SupernodalFactor {
  int n = 0, nsuper = 0;
  const int* super = nullptr;
  const int* pi = nullptr;
  const int* px = nullptr;
  const int* rows = nullptr;
  const int* perm = nullptr;
  const double* values = nullptr;
};

class ParallelSubstitution {
 public:
  void plan(const SupernodalFactor& factor, int threads);
  int threads() const { return static_cast<int>(groups_.size()); }
  double top_fraction() const { return top_fraction_; }  // share of entries solved serially
  // x = (L L')^-1 applied to b in the original ordering.
  void solve(const double* b, double* x);

 private:
  void forward(int s, double* acc, double* w);
  void backward(int s, double* w);

  SupernodalFactor L_;
  std::vector<std::vector<std::pair<int, int>>> groups_;  // per thread: supernode ranges
  std::vector<int> top_;                                  // top supernodes, increasing
  std::vector<char> top_row_;                             // per row: owned by a top supernode
  std::vector<int> top_rows_;
  std::vector<std::vector<double>> acc_, work_;
  std::vector<double> y_;
  double top_fraction_ = 1;
};

}  // namespace pfv
