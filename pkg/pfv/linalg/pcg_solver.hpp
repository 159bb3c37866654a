// Conjugate gradients on G, preconditioned by an incomplete Cholesky factor computed once per
// remesh and warm-started from the previous pressures (useSolver=1, a PFV extension).
// Between remeshes the right-hand side changes little, so few iterations are needed.
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/pressure_solver.hpp"

namespace pfv {

class PcgSolver final : public PressureSolver {
 public:
  PcgSolver();
  ~PcgSolver() override;
  PcgSolver(const PcgSolver&) = delete;
  PcgSolver& operator=(const PcgSolver&) = delete;

  // Throws std::domain_error if the preconditioner cannot be built (a singular system).
  void setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& options) override;
  SolverKind kind() const override { return SolverKind::kConjugateGradient; }
  bool ready() const override;
  // Stops at |r| <= tolerance |b|.
  SolveStats solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) override;
  // To control.inverse_tolerance from zero.
  void apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) const override;
  void release() override;
  double error() const { return error_; }  // |r| / |b| of the last solve

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  double error_ = 0;
};

}  // namespace pfv
