#include "pfv/linalg/pcg_solver.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <stdexcept>

namespace pfv {

struct PcgSolver::Impl {
  Eigen::SparseMatrix<double> g;  // G's upper triangle, copied: the factorisation reads it
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::IncompleteCholesky<double, Eigen::Upper>>
      cg;
  bool ready = false;

  // Returns the iterations made and the final |r| / |b|.
  std::pair<int, double> run(const std::vector<double>& rhs, std::vector<double>& x, double tolerance,
                             int max_iterations) {
    const Eigen::Index n = static_cast<Eigen::Index>(rhs.size());
    cg.setTolerance(tolerance);
    cg.setMaxIterations(max_iterations);
    Eigen::Map<const Eigen::VectorXd> b(rhs.data(), n);
    Eigen::Map<Eigen::VectorXd> guess(x.data(), n);
    Eigen::VectorXd result = cg.solveWithGuess(b, guess);
    guess = result;
    return {static_cast<int>(cg.iterations()), cg.error()};
  }
};

PcgSolver::PcgSolver() : impl_(std::make_unique<Impl>()) {}
PcgSolver::~PcgSolver() = default;

bool PcgSolver::ready() const { return impl_->ready; }

void PcgSolver::release() { impl_ = std::make_unique<Impl>(); }

void PcgSolver::setup(std::shared_ptr<const SymmetricMatrix> matrix, const SolverOptions&) {
  const SymmetricMatrix& s = *matrix;
  const int n = s.size();
  impl_->ready = false;
  impl_->g = Eigen::Map<const Eigen::SparseMatrix<double>>(n, n, static_cast<Eigen::Index>(s.value.size()),
                                                           s.col_start.data(), s.row.data(), s.value.data());
  impl_->cg.compute(impl_->g);
  if (impl_->cg.info() != Eigen::Success)
    throw std::domain_error("incomplete Cholesky preconditioner failed (is the system singular?)");
  impl_->ready = true;
}

SolveStats PcgSolver::solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) {
  SolveStats stats;
  const auto [iterations, error] = impl_->run(b, x, control.tolerance, control.max_iterations);
  stats.cg_iterations = iterations;
  stats.converged = error <= control.tolerance;
  error_ = error;
  return stats;
}

void PcgSolver::apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) const {
  x.assign(impl_->g.rows(), 0.0);
  impl_->run(b, x, control.inverse_tolerance, control.max_iterations);
}

}  // namespace pfv
