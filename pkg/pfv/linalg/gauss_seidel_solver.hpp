// Successive over-relaxation on the cell adjacency, warm-started from the previous pressures,
// stopped by the thesis' rule max|dp| / max|p| < tolerance (5.5).
#pragma once
#include <vector>

#include "pfv/linalg/pressure_solver.hpp"

namespace pfv {

class GaussSeidelSolver final : public PressureSolver {
 public:
  SolverKind kind() const override { return SolverKind::kGaussSeidel; }
  bool ready() const override { return true; }  // nothing to prepare
  SolveStats solve(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                   const SolveControl& control) override;
  // A tight solve (1e-10) from zero.
  void apply_inverse(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                     const SolveControl& control) const override;
};

}  // namespace pfv
