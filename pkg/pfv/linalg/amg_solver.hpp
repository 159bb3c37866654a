// The multigrid pressure solver (a PFV extension, solver="multigrid"): conjugate gradients
// preconditioned by BoomerAMG (amg_pcg.hpp) on this process, the hierarchy built once per
// system, every solve started from the projection of the new solution onto the span of the last
// solutions on this system (solution_history.hpp) and the caller's start (the last step's
// pressures, or after a remesh those interpolated from the old mesh), and stopped by the
// refinement's rule (within refinement_tolerance of the pressure spread). Its memory grows as
// O(N): the choice when a Cholesky factor would not fit (engine/solver_policy.hpp). Built only
// with hypre (PFV_WITH_HYPRE).
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/amg_pcg.hpp"
#include "pfv/linalg/pressure_solver.hpp"

namespace pfv {

// Solutions the engine's solver keeps for its start: the span of the last three holds a solution
// quadratic in time, which a packing moving at constant velocities has between remeshes (its cell
// volumes are cubic in time); on a drifting lattice the third difference they miss is 0.14-0.22 x
// the default bound, below the error the solves leave in them. A fourth would cost 16 more bytes
// per unknown.
inline constexpr int kEngineStartHistory = 3;

// hypre's settings for a smoother of the V-cycle (its relax types), keeping kEngineStartHistory
// solutions.
AmgParameters amg_parameters(MultigridSmoother smoother);

class AmgSolver final : public PressureSolver {
 public:
  // Reads options.multigrid_smoother. Throws std::runtime_error if hypre or MPI fails.
  void setup(std::shared_ptr<const SymmetricMatrix> g, const SolverOptions& options) override;
  // With hypre's settings given in full (tests, benchmarks).
  void setup(const SymmetricMatrix& g, const AmgParameters& parameters);
  SolverKind kind() const override { return SolverKind::kMultigrid; }
  bool ready() const override { return pcg_ != nullptr; }
  SolveStats solve(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) override;
  // To control.inverse_tolerance (|r| / |b|) from zero.
  void apply_inverse(const std::vector<double>& b, std::vector<double>& x, const SolveControl& control) const override;
  // The start is the solver's own (above): the engine passes its last pressures.
  bool wants_extrapolated_start() const override { return false; }
  void release() override { pcg_.reset(); }

  const AmgPcg* hierarchy() const { return pcg_.get(); }

 private:
  std::unique_ptr<AmgPcg> pcg_;
  int n_ = 0;
};

}  // namespace pfv
