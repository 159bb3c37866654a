#include "pcg_solver.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>
#include <stdexcept>

#include "pressure_system.hpp"

namespace pfv {

struct PcgSolver::Impl {
  Eigen::SparseMatrix<double> g;  // upper triangle, as assembled
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Upper, Eigen::IncompleteCholesky<double, Eigen::Upper>> cg;
  bool ready = false;
};

PcgSolver::PcgSolver() : impl_(std::make_unique<Impl>()) {}
PcgSolver::~PcgSolver() = default;
PcgSolver::PcgSolver(PcgSolver&&) noexcept = default;
PcgSolver& PcgSolver::operator=(PcgSolver&&) noexcept = default;

bool PcgSolver::ready() const { return impl_->ready; }

void PcgSolver::setup(const PressureSystem& s) {
  const int n = s.n_unknowns();
  impl_->g = Eigen::Map<const Eigen::SparseMatrix<double>>(n, n, static_cast<Eigen::Index>(s.value.size()),
                                                          s.col_start.data(), s.row.data(), s.value.data());
  impl_->cg.compute(impl_->g);
  if (impl_->cg.info() != Eigen::Success)
    throw std::domain_error("incomplete Cholesky preconditioner failed (is the system singular?)");
  impl_->ready = true;
}

void PcgSolver::solve(const std::vector<double>& rhs, std::vector<double>& x, double tolerance, int max_iterations) {
  const Eigen::Index n = static_cast<Eigen::Index>(rhs.size());
  impl_->cg.setTolerance(tolerance);
  impl_->cg.setMaxIterations(max_iterations);
  Eigen::Map<const Eigen::VectorXd> b(rhs.data(), n);
  Eigen::Map<Eigen::VectorXd> guess(x.data(), n);
  Eigen::VectorXd result = impl_->cg.solveWithGuess(b, guess);
  guess = result;
  iterations_ = static_cast<int>(impl_->cg.iterations());
  error_ = impl_->cg.error();
}

}  // namespace pfv
