// Conjugate gradients on G preconditioned by one V-cycle of algebraic multigrid (the hierarchy
// hypre's BoomerAMG builds), over the rows of G one MPI process owns: a pressure solve whose
// memory grows as O(N), where the Cholesky factor grows as N^(4/3) on a three-dimensional pore
// network. On one process the V-cycle, the products with G and the vector operations are PFV's,
// on the OpenMP team or on one thread with the same bits (amg_cycle.hpp); on several, hypre's.
//
// The hierarchy is built once per system (at a remesh) and reused by every solve. The
// iteration is written here, not taken from hypre's PCG, for its stopping rule: the engine's
// pressures are accurate relative to their spread (max p - min p), as the refinement of a
// 32-bit factor is (refinement.hpp), and hypre's Krylov solvers stop on residual norms only.
// A solve stops once the estimated error rho / (1 - rho) * max |update| is below
// tolerance * spread. rho is the largest ratio of successive update norms in this solve, and at
// least the largest ratio of the last solve on this system that made three iterations or more
// (two ratios): the first ratio of a solve is often far below the contraction that follows (the
// first update takes out most of a smooth start error), and a solve of two iterations judged by
// it alone left pressures up to 1.4 times the bound from the direct solve's (a drifting lattice,
// multigrid_start_test.cpp). The ratios of CG's updates swing from one iteration to the next, so
// the last two alone can promise a contraction the iteration does not keep: with them, pressures
// came out up to 1.7 times the bound (multigrid_solver_test.cpp). An update larger than the one
// before restarts the estimate (CG's updates need not shrink every time; a weak preconditioner
// makes them swing past 1), and from the second iteration on one below 1e-3 of the bound stops
// the solve whatever the ratios (at the rounding floor they are noise). The first iteration has
// no ratio of its own: it takes twice that last measured ratio (as the refinement seeds its
// contraction), or halfway from it to 1 where that is less, and without one it does not stop,
// however small its update: a good start leaves a small first update whatever error remains in
// the modes the V-cycle reduces slowly. The first solve on a system goes on to 1e-8 of the
// spread at least (when the tolerance is looser), so that the ratio the later solves rely on is
// measured over enough iterations; on a system without one, a solve does not stop on a single
// ratio either. At refinement_tolerance 1e-4 in a moving packing, pressures came out 2.4 times the
// bound without these (multigrid_start_test.cpp).
//
// The start (AmgParameters::start_history > 0, as the engine's solver sets it) is extrapolated
// in time from the last solutions on this system, of the order whose residual is the smallest
// (solution_history.hpp): between remeshes, in a smooth motion, one iteration (one V-cycle, two
// products with G) is then the common case.
//
// MPI: a system distributed over the processes of a communicator (each owns a contiguous range
// of rows, with global column indices) is solved by the same code as a local one on
// MPI_COMM_SELF. The engine solves locally; bench/amg/ solves a saved system over two processes.
#pragma once
#include <mpi.h>

#include <array>
#include <memory>
#include <vector>

#include "pfv/linalg/distributed_rows.hpp"

namespace pfv {

// BoomerAMG's settings for a three-dimensional scalar diffusion operator (hypre's manual,
// "BoomerAMG": HMIS coarsening with extended+i interpolation truncated to a few entries per row,
// a strength threshold of 0.5 in 3D), with a symmetric smoother so that the V-cycle is a
// symmetric preconditioner for CG.
//
// The smoother is the symmetric l1-Gauss-Seidel sweep pair (relax_type 8); l1-scaled Jacobi
// (18) reads each level's matrix half as often per iteration but needs more iterations, and
// its slower contraction makes the stopping rule's first-iteration test more cautious: it costs
// less per step where the start is exact for many steps (a fixed skeleton), more where the
// start is close but not exact. One forward sweep down and one backward sweep up (relax_down
// 13, relax_up 14) also halves the sweeps, for about one more iteration (doc/solvers.md,
// bench/multigrid_smoothers.py).
struct AmgParameters {
  double strong_threshold = 0.5;
  int coarsen_type = 10;  // HMIS
  int interp_type = 6;    // extended+i
  int max_row_entries = 4;
  int relax_type = 8;  // symmetric l1-Gauss-Seidel, where relax_down, relax_up are -1 (18: l1-scaled Jacobi)
  // The smoothers on the way down and up the V-cycle, e.g. l1-scaled hybrid Gauss-Seidel forwards
  // down (13), backwards up (14): the cycle stays symmetric, as CG needs, with one sweep per level
  // and direction where the symmetric Gauss-Seidel makes two (bench/amg/amg_solve.cpp).
  int relax_down = -1, relax_up = -1;
  int aggressive_levels = 0;  // levels of aggressive coarsening (less memory, more iterations)
  // On one process, with the smoothers above (8, 18, or 13 down and 14 up), the V-cycle is PFV's
  // (amg_cycle.hpp: on the threads, hypre's copies freed); true keeps hypre's, for comparison.
  // Other relax types and several processes always run hypre's.
  bool hypre_cycle = false;
  int print_level = 0;  // hypre's report of the hierarchy (1: at set-up, on stdout)
  // Solutions (and their products with G) kept to start the next solve from (solve(), below); 0:
  // every solve starts from the x it is given. At most kMaxStartHistory.
  int start_history = 0;
  static constexpr int kMaxStartHistory = 4;
};

struct AmgSolveStats {
  int iterations = 0;
  bool converged = false;
  double relative_residual = 0;  // |b - G x| / |b| on return (solve_to_residual only)
};

// Ensures MPI (a singleton process when not started by mpirun) and hypre are initialised;
// throws std::runtime_error if MPI cannot start. Finalisation is left to process exit.
void ensure_hypre_initialized();

class AmgPcg {
 public:
  // Builds the matrix and its multigrid hierarchy; collective over comm. Throws
  // std::invalid_argument on rows that do not describe a square block of a global matrix,
  // std::runtime_error if hypre fails.
  AmgPcg(MPI_Comm comm, const DistributedRows& rows, const AmgParameters& parameters = {});
  ~AmgPcg();
  AmgPcg(const AmgPcg&) = delete;
  AmgPcg& operator=(const AmgPcg&) = delete;

  // x (this process's rows) holds the start and returns the solution; stops by the spread rule
  // above. With a start history, x is taken into the history (it is the last step's solution, or
  // pressures the history lacks) and the solve starts from the history's extrapolation; the
  // solution is kept provisionally: a caller that passes it back as the next start confirms it,
  // one that passes other values (it dropped the step) removes it. Collective.
  // step: the time since the last solve (the DEM step), for the history's extrapolation in time.
  AmgSolveStats solve(const std::vector<double>& b, std::vector<double>& x, double tolerance, int max_iterations,
                      double step = 1);
  // Stops at |b - G x| <= relative_residual |b| instead; x = 0 on entry gives G^-1 b.
  AmgSolveStats solve_to_residual(const std::vector<double>& b, std::vector<double>& x, double relative_residual,
                                  int max_iterations) const;

  int levels() const;
  // Solutions kept for the start of the next solve (at most AmgParameters::start_history).
  int kept_solutions() const;
  // hypre's smoother (relax type) on the way down and on the way up the V-cycle, as set up.
  std::array<int, 2> cycle_relax_types() const;
  // Entries of all levels' matrices over those of G (hypre's operator complexity).
  double operator_complexity() const { return operator_complexity_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double operator_complexity_ = 0;
  int levels_ = 0;
  std::array<int, 2> relax_types_{};
  double seen_ratio_ = 0;  // the largest update ratio of the last solve with three iterations or more
};

}  // namespace pfv
