// The direct solver: G's sparse Cholesky factor (CHOLMOD, cholmod_solver.hpp), computed once per
// system and reused for every step's substitution. With a 32-bit factor each solve is an
// iterative refinement in double (refinement.hpp), promoted to a double factor if G turns out
// too ill-conditioned for it.
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/cholmod_solver.hpp"
#include "pfv/linalg/matrix_rows.hpp"
#include "pfv/linalg/pressure_solver.hpp"
#include "pfv/linalg/refinement.hpp"

namespace pfv {

class CholeskySolver final : public PressureSolver {
 public:
  // Reads options.factor. Throws std::domain_error if G is not positive definite,
  // FactorTooLarge (cholmod_solver.hpp) beyond options.factor.max_entries or index_range.
  void setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& options) override;
  SolverKind kind() const override { return SolverKind::kCholesky; }
  bool ready() const override { return factor_.ready(); }
  SolveStats solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) override;
  // One substitution (an approximate inverse to 1e-8 with a 32-bit factor).
  void apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) const override;
  bool wants_extrapolated_start() const override { return factor_.reduced_precision(); }
  // Frees the factor; keeps the storage of its values and the contraction seen so far.
  void release() override;
  // Takes what an earlier solver of the same engine learnt: the largest refinement contraction
  // of its factors, the seed of this factor's first solve (Refinement::seed).
  void carry_over(const CholeskySolver& previous);

  const CholmodSolver& factor() const { return factor_; }
  double refinement_contraction() const { return refinement_.contraction(); }
  // G by rows, as the refinement reads it (empty with a double factor).
  const MatrixRows& rows() const { return rows_; }

 private:
  // solve() of the factor writes scratch buffers only, so apply_inverse stays const.
  mutable CholmodSolver factor_;
  std::shared_ptr<const SymmetricMatrix> g_;
  MatrixRows rows_;  // G by rows for the refinement's residual: with a 32-bit factor only
  Refinement refinement_;
  double contraction_seen_ = -1;  // the largest refinement contraction of this solver's factors
};

}  // namespace pfv
