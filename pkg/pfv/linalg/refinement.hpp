// Iterative refinement of G x = b with an approximate factor M ~ G (the factor rounded to
// 32-bit integers scaled per column, cholmod_solver.hpp): x <- x + M^-1 (b - G x), the residual
// in double.
//
// The iteration contracts the error by rho = ||I - M^-1 G|| per pass, of order 1e-8 on pore
// networks (doc/solvers.md), and it starts from pressures that differ from the new ones by
// about the change of one DEM step (a small fraction of their spread): one pass
// meets a tolerance of 1e-10 while it reads half the bytes of a double substitution (plus G
// once, for the residual). rho is estimated before a factor's first solve by a few power
// iterations on I - M^-1 G (times a safety factor: the power iteration approaches rho from
// below), unless seeded from an earlier factor (seed()); a solve stops as soon as the
// estimated error rho / (1 - rho) * |correction| is below the tolerance, relative to the spread
// max x - min x of the solution (max |x| if it is uniform).
// A pass that contracts less than rho raises it. (The ratio of the first two corrections is
// no estimate: on an ill-conditioned G it can be tiny while the iteration diverges.)
#pragma once
#include <vector>

#include "pfv/common/parallel.hpp"
#include "pfv/linalg/matrix_rows.hpp"
#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

class CholmodSolver;

class Refinement {
 public:
  // Forget rho (a new factor).
  void reset() { rho_ = seed_ = -1; }
  // rho measured on an earlier factor of the same engine (the previous mesh), taken as this
  // factor's instead of the power iterations, which cost one residual and one substitution each
  // at every remesh. Consecutive meshes of one packing contract alike, and the first solve of a
  // mesh starts cold (two passes or more), so a pass contracting less than the seed raises rho
  // as below. (One power iteration is no check: from the fixed start its ratio is 20x rho.)
  void seed(double rho) { seed_ = rho; }
  // rows: G by rows (index_rows), or empty to read its columns. x holds the starting guess on
  // entry. Returns false if the passes stop contracting
  // (rho >= 1/2: G is too ill-conditioned for the rounded factor) or max_passes is reached;
  // x is then unspecified.
  bool solve(const SymmetricMatrix& g, const MatrixRows& rows, CholmodSolver& factor, const std::vector<double>& b,
             std::vector<double>& x, double tolerance, int max_passes);
  int passes() const { return passes_; }
  double contraction() const { return rho_; }  // -1 until measured

  static constexpr int kPowerIterations = 4;
  static constexpr double kSafety = 4;

 private:
  double estimate_contraction(const SymmetricMatrix& g, const MatrixRows& rows, CholmodSolver& factor);

  std::vector<double> residual_, correction_;
  LoopChoice residual_loop_;  // one thread or the team for the residual, by measured time
  double rho_ = -1, seed_ = -1;
  int passes_ = 0;
};

// r = b - G x: from G's rows unless rows is empty, else from its upper triangle by column. By
// rows on the OpenMP team above kMinParallelLoop rows, or as `choice` measures (the same bits).
void residual(const SymmetricMatrix& g, const MatrixRows& rows, const std::vector<double>& b,
              const std::vector<double>& x, std::vector<double>& r, LoopChoice* choice = nullptr);

}  // namespace pfv
