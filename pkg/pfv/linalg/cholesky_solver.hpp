// The direct solver: G's sparse Cholesky factor (CHOLMOD, cholmod_solver.hpp), computed once per
// system and reused for every step's substitution. With a 32-bit factor each solve is an
// iterative refinement in double (refinement.hpp), promoted to a double factor if G turns out
// too ill-conditioned for it.
#pragma once
#include <limits>
#include <vector>

#include "pfv/linalg/cholmod_solver.hpp"
#include "pfv/linalg/pressure_solver.hpp"
#include "pfv/linalg/refinement.hpp"

namespace pfv {

struct FactorOptions {
  Ordering ordering = Ordering::kAuto;
  FactorPrecision precision = FactorPrecision::kDouble;
  GivenOrdering given;
  double min_scaled_entries = 0;  // a 32-bit factor only from this many stored entries
  bool openmp_teams = false;      // EngineSettings::cholmod_openmp_teams
  // setup() throws FactorTooLarge, having spent only the analysis, beyond this many values.
  double max_entries = std::numeric_limits<double>::infinity();
  double index_range = CholmodSolver::kMaxIndexedValues;  // lowered by tests only (set_index_range_for_test)
};

class CholeskySolver final : public PressureSolver {
 public:
  // Throws std::domain_error if G is not positive definite, FactorTooLarge (cholmod_solver.hpp)
  // beyond options.max_entries or options.index_range.
  void setup(const PressureSystem& system, const FactorOptions& options);
  SolverKind kind() const override { return SolverKind::kCholesky; }
  bool ready() const override { return factor_.ready(); }
  SolveStats solve(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                   const SolveControl& control) override;
  // One substitution (an approximate inverse to 1e-8 with a 32-bit factor).
  void apply_inverse(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                     const SolveControl& control) const override;
  bool wants_extrapolated_start() const override { return factor_.reduced_precision(); }
  // Frees the factor; keeps the storage of its values and the contraction seen so far.
  void release() override { factor_.release(); }
  // Takes what an earlier solver of the same engine learnt: the largest refinement contraction
  // of its factors, the seed of this factor's first solve (Refinement::seed).
  void carry_over(const CholeskySolver& previous);

  const CholmodSolver& factor() const { return factor_; }
  double refinement_contraction() const { return refinement_.contraction(); }

 private:
  // solve() of the factor writes scratch buffers only, so apply_inverse stays const.
  mutable CholmodSolver factor_;
  Refinement refinement_;
  double contraction_seen_ = -1;  // the largest refinement contraction of this solver's factors
};

}  // namespace pfv
