#include "pfv/linalg/amg_solver.hpp"

#include "pfv/linalg/distributed_rows.hpp"

namespace pfv {

AmgParameters amg_parameters(MultigridSmoother smoother) {
  AmgParameters parameters;
  parameters.start_history = kEngineStartHistory;
  if (smoother == MultigridSmoother::kJacobi) parameters.relax_type = 18;  // l1-scaled Jacobi
  if (smoother == MultigridSmoother::kSplitGaussSeidel) {
    parameters.relax_down = 13;  // l1-scaled Gauss-Seidel, forwards
    parameters.relax_up = 14;    // and backwards: the adjoint, so the cycle stays symmetric
  }
  return parameters;
}

void AmgSolver::setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& options) {
  setup(*g, amg_parameters(options.multigrid_smoother));
}

void AmgSolver::setup(const SymmetricMatrix& g, const AmgParameters& parameters) {
  pcg_.reset();
  n_ = g.size();
  pcg_ = std::make_unique<AmgPcg>(MPI_COMM_SELF, full_rows(g), parameters);
}

SolveStats AmgSolver::solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) {
  const AmgSolveStats s = pcg_->solve(b, x, control.refinement_tolerance, control.max_iterations, control.time_step);
  SolveStats stats;
  stats.cg_iterations = s.iterations;
  stats.converged = s.converged;
  return stats;
}

void AmgSolver::apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) const {
  x.assign(n_, 0.0);
  pcg_->solve_to_residual(b, x, control.inverse_tolerance, control.max_iterations);
}

}  // namespace pfv
