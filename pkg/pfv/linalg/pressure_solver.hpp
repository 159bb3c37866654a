// One interface for the ways of solving G p = b over the unknown cells: Gauss-Seidel (YADE's
// useSolver=0), conjugate gradients with an incomplete Cholesky preconditioner (a PFV
// extension, useSolver=1), the sparse Cholesky factor (useSolver=3) and conjugate gradients
// with an algebraic multigrid preconditioner (a PFV extension, amg_solver.hpp). kAuto, the
// default, is the Cholesky factor unless it would not fit in memory or would cost more per
// step than multigrid (engine/solver_policy.hpp); it names a choice, never a solver.
//
// As MFEM's Solver (SetOperator, then Mult): a solver is set up once per system with G (a
// factorisation, a preconditioner, nothing), keeps G, and then solves many right-hand sides
// with it: one per DEM step between two remeshes. Which solver, and when, is the engine's
// solver policy (engine/solver_policy.hpp).
#pragma once
#include <memory>
#include <string_view>
#include <vector>

#include "pfv/linalg/solver_options.hpp"
#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

enum class SolverKind { kGaussSeidel, kConjugateGradient, kCholesky, kMultigrid, kAuto };

// The smoother's name in the Python API: gauss_seidel, jacobi, split_gauss_seidel.
std::string_view to_string(MultigridSmoother smoother);

std::string_view to_string(SolverKind kind);

// Stopping rules; each solver reads the ones that concern it.
struct SolveControl {
  double tolerance = 1e-6;  // Gauss-Seidel's max|dp|/max|p|, incomplete-Cholesky CG's |r|/|b|
  double relax = 1.9;       // Gauss-Seidel over-relaxation
  int max_iterations = 200000;
  // Refinement with a 32-bit factor and multigrid CG: estimated error relative to the spread of p.
  double refinement_tolerance = 1e-10;
  int max_refinement_passes = 8;
  // apply_inverse of the iterative solvers: |r|/|b| (Gauss-Seidel: max|dx|/max|x|). The
  // eigenvalue estimates need it tight; a caller that certifies its own result may loosen it.
  double inverse_tolerance = 1e-10;
  // The time since the last solve (the DEM step): multigrid extrapolates its start in time.
  double time_step = 1;
};

// What the last solve did, each count named for what it counts.
struct SolveStats {
  int sweeps = 0;             // Gauss-Seidel sweeps over the unknowns
  int cg_iterations = 0;      // conjugate-gradient iterations (either preconditioner)
  int refinement_passes = 0;  // refinement passes with a 32-bit factor (0 with a double factor)
  bool converged = true;      // false: an iterative solver stopped at max_iterations
};

class PressureSolver {
 public:
  virtual ~PressureSolver() = default;
  virtual SolverKind kind() const = 0;
  // Prepares the solves with G (of at least one unknown) and keeps it for them; throws as each
  // solver says, and is then not ready().
  virtual void setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& options) = 0;
  // Ready for solve() with the G it was set up with.
  virtual bool ready() const = 0;
  // x (one entry per unknown) holds the start on entry and the solution on return; b includes
  // the couplings to the Dirichlet cells.
  virtual SolveStats solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) = 0;
  // x ~ G^-1 b to control.inverse_tolerance (exact with a factor), from x = 0, without changing
  // what the next solve() does: the stability limit's operator.
  virtual void apply_inverse(const std::vector<double>& b, std::vector<double>& x,
                             const SolveControl& control) const = 0;
  // Whether the next solve() should start from pressures extrapolated from the last two steps
  // rather than the last step's (refinement: it halves the first correction in a smooth motion).
  virtual bool wants_extrapolated_start() const { return false; }
  // Frees what was built for the last system, G included, keeping what the next setup can reuse.
  virtual void release() {}
};

}  // namespace pfv
