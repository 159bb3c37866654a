// One V-cycle of algebraic multigrid over a hierarchy of plain compressed rows, on one thread or
// on the calling thread's team with the same bits: the multigrid solver's preconditioner
// (amg_pcg.hpp) on a single process. Columns outside a row's block are renumbered into a halo
// of the level's values copied before each sweep, so that a row is one loop (CsrRows' columns
// as given are kept only for the system's own products, multiply()).
//
// hypre builds the hierarchy (its coarsening and interpolation are what it does well), and its
// V-cycle would do for the solve too, but Debian builds hypre without OpenMP: its cycle runs on
// one thread, which left the two-thread flow step of a 200 000-sphere packing 1.14 times faster
// where YADE's DEM step gains 1.67 times. The cycle here reads the levels' matrices and
// interpolations copied out of hypre's set-up, and hypre's own copies are freed.
//
// The Gauss-Seidel smoothers are hybrid (Baker, Falgout, Kolev and Yang, "Multigrid smoothers
// for ultraparallel computing", SIAM J. Sci. Comput. 33, 2011): each level's rows fall in
// contiguous blocks, swept by Gauss-Seidel inside a block and by Jacobi across blocks (a row
// reads the values the other blocks had before the sweep), each row scaled by its l1 diagonal,
// a_ii + the sum of |a_ij| over the columns outside its block, which keeps the sweep convergent
// for any positive definite level matrix and any blocks. The blocks are fixed by the level's size,
// not by the threads, so the cycle gives the same bits on any number of threads: a level of
// fewer than kRowsPerBlock rows is one block, plain Gauss-Seidel as hypre's one-thread cycle.
// The forward sweep's adjoint is the backward sweep over the same blocks, so the cycles stay
// symmetric, as conjugate gradients needs (MultigridSmoother). The coarsest level is solved
// directly (a dense LDL^T, which also takes a semidefinite level).
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/solver_options.hpp"

namespace pfv {

// Compressed rows of a level's matrix or of an interpolation (local column indices).
struct CsrRows {
  int n_rows = 0, n_cols = 0;
  std::vector<int> start{0};  // n_rows + 1 entries
  std::vector<int> column;
  std::vector<double> value;
};

// The dot product summed over fixed chunks (kSumChunks, parallel.hpp), added in order: the same
// bits on one thread as on the team.
double fixed_chunk_dot(const double* a, const double* b, int n, bool team);

class AmgCycle {
 public:
  // A level's rows per Gauss-Seidel block, up to kMaxBlocks blocks: the rows a block shares
  // with others sweep as Jacobi, and their values are copied before each sweep, so the blocks
  // are large. In the engine's breadth-first cell order a block is a shell of the packing: with
  // 64 blocks 82 % of the finest level's rows of a 200 000-sphere lattice read other blocks,
  // and a sweep took 1.4 times as long as with 16 (which also bound the threads a level uses).
  static constexpr int kRowsPerBlock = 8192;
  static constexpr int kMaxBlocks = 16;
  // A coarsest level beyond this many rows is not factorised (dense) but smoothed by this
  // many symmetric sweeps: hypre coarsens to at most 9 rows unless its coarsening stalls.
  static constexpr int kMaxDenseRows = 2000;
  static constexpr int kCoarsestSweeps = 8;

  // a[l]: level l's matrix (a[0] is the system's), p[l]: the interpolation from level l + 1 to
  // level l (a.size() - 1 of them). Throws std::invalid_argument on shapes that do not chain.
  AmgCycle(std::vector<CsrRows> a, std::vector<CsrRows> p, MultigridSmoother smoother);
  ~AmgCycle();
  AmgCycle(const AmgCycle&) = delete;
  AmgCycle& operator=(const AmgCycle&) = delete;

  int levels() const { return static_cast<int>(levels_.size()); }
  int size() const { return levels_.front().n(); }
  // Entries of every level's matrix over those of the system's.
  double operator_complexity() const;

  // z = M^-1 r: one V-cycle from zero. team: on the calling thread's team (levels of at least
  // kMinParallelLoop rows), or on the calling thread; the bits are the same.
  void apply(const double* r, double* z, bool team) const;
  // y = alpha A x + beta y with the system's matrix (beta 0: y is not read).
  void multiply(double alpha, const double* x, double beta, double* y, bool team) const;

 private:
  struct Level {
    // The level's matrix, its columns outside the row's block renumbered n + k: the k-th entry of
    // halo, whose value the sweep reads from before the sweep. Every product with the level's
    // matrix reads x extended by those values (x_ext), so one loop per row serves both.
    CsrRows a;
    std::vector<int> halo;  // the rows read from other blocks, once each
    CsrRows p, r;           // interpolation from the next level and its transpose (none on the coarsest)
    std::vector<int> block_start;
    std::vector<double> inverse_diagonal;  // the smoother's: 1 / l1 diagonal
    // x extended by the halo's values (n + halo.size()), the right-hand side (level 0 reads the
    // caller's), and room for the residual or for the values before a Jacobi sweep.
    mutable std::vector<double> x_ext, b, work;
    int n() const { return a.n_rows; }
  };
  struct Coarsest;

  void smooth(const Level& level, const double* b, bool down, bool team) const;
  void refresh_halo(const Level& level, bool team) const;
  void sweep(const Level& level, const double* b, bool forward, bool from_zero, bool team) const;
  void jacobi(const Level& level, const double* b, bool from_zero, bool team) const;
  void solve_coarsest(const double* b, bool team) const;

  std::vector<int> system_column_;  // level 0's columns as given, for multiply()
  std::vector<Level> levels_;
  std::unique_ptr<Coarsest> coarsest_;
  MultigridSmoother smoother_;
};

}  // namespace pfv
