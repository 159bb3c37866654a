// The multigrid pressure solver (a PFV extension, solver="multigrid"): conjugate gradients
// preconditioned by BoomerAMG (amg_pcg.hpp) on this process, the hierarchy built once per
// system, every solve warm-started from the pressures extrapolated from the last two steps and
// stopped by the refinement's rule (within refinement_tolerance of the pressure spread). Its
// memory grows as O(N): the choice when a Cholesky factor would not fit (linear_system.hpp).
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/amg_pcg.hpp"
#include "pfv/linalg/pressure_solver.hpp"

namespace pfv {

class AmgSolver final : public PressureSolver {
 public:
  // Throws std::runtime_error if hypre or MPI fails.
  void setup(const PressureSystem& system, const AmgParameters& parameters = {});
  SolverKind kind() const override { return SolverKind::kMultigrid; }
  bool ready() const override { return pcg_ != nullptr; }
  SolveStats solve(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                   const SolveControl& control) override;
  // To |r| <= 1e-10 |b| from zero.
  void apply_inverse(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                     const SolveControl& control) const override;
  bool wants_extrapolated_start() const override { return true; }
  void release() override { pcg_.reset(); }

  const AmgPcg* hierarchy() const { return pcg_.get(); }

 private:
  std::unique_ptr<AmgPcg> pcg_;
};

// G's full rows (both triangles) from its stored upper triangle: one process's whole matrix.
DistributedRows full_rows(const PressureSystem& system);

}  // namespace pfv
