#include "pfv/linalg/cholesky_solver.hpp"

#include <algorithm>

namespace pfv {

void CholeskySolver::setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& all) {
  const FactorOptions& options = all.factor;
  refinement_.reset();
  g_.reset();
  rows_ = {};
  factor_.set_openmp_teams(options.openmp_teams);
  factor_.set_max_entries(options.max_entries);
  factor_.set_index_range_for_test(options.index_range);
  factor_.factorize(*g, options.ordering, options.precision, options.given, options.min_scaled_entries);
  // The refinement's residual reads G by rows; a double factor never does.
  if (factor_.reduced_precision()) rows_ = index_rows(*g);
  g_ = std::move(g);
}

void CholeskySolver::release() {
  factor_.release();
  g_.reset();
  rows_ = {};
}

SolveStats CholeskySolver::solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) {
  SolveStats stats;
  if (!factor_.reduced_precision()) {
    factor_.solve(b, x);
    return stats;
  }
  if (refinement_.contraction() < 0 && contraction_seen_ > 0) refinement_.seed(contraction_seen_);
  const bool converged =
      refinement_.solve(*g_, rows_, factor_, b, x, control.refinement_tolerance, control.max_refinement_passes);
  stats.refinement_passes = refinement_.passes();
  if (converged) {
    contraction_seen_ = std::max(contraction_seen_, refinement_.contraction());
  } else {
    factor_.promote_to_double(*g_);  // G too ill-conditioned for the 32-bit factor
    factor_.solve(b, x);
  }
  return stats;
}

void CholeskySolver::apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl&) const {
  factor_.solve(b, x);
}

void CholeskySolver::carry_over(const CholeskySolver& previous) {
  contraction_seen_ = std::max(contraction_seen_, previous.contraction_seen_);
}

}  // namespace pfv
