// Successive over-relaxation on G's rows, warm-started from the previous pressures, stopped by
// the thesis' rule max|dp| / max|p| < tolerance (5.5).
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/matrix_rows.hpp"
#include "pfv/linalg/pressure_solver.hpp"

namespace pfv {

class GaussSeidelSolver final : public PressureSolver {
 public:
  SolverKind kind() const override { return SolverKind::kGaussSeidel; }
  // Copies G by rows (matrix_rows.hpp): a sweep reads each unknown's neighbours in one place.
  void setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& options) override;
  bool ready() const override { return !rows_.empty(); }
  SolveStats solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) override;
  // A tight solve (control.inverse_tolerance) from zero.
  void apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) const override;
  void release() override { rows_ = {}; }

 private:
  MatrixRows rows_;
};

}  // namespace pfv
