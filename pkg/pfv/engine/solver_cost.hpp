// The cost model by which solver = auto chooses between the Cholesky factor and multigrid when
// both fit in memory: the time per DEM step of each, its set-up (factorisation, hierarchy)
// spread over the steps a system serves. It counts only what the engine knows exactly (the
// factor's values from CHOLMOD's analysis, the unknowns, multigrid's CG iterations per step seen
// on the last system, the remesh schedule), weighted by per-unit costs measured on the
// benchmark lattice at one thread (doc/solvers.md, "solver = auto"): the choice is the same on
// every run of a scene, whatever the machine's load, and only the ratio of the weights matters.
#pragma once
#include <vector>

#include "pfv/engine/engine_settings.hpp"

namespace pfv {

// What the engine saw of the solves of its last linear system, for the next choice.
struct SolveHistory {
  // Multigrid's CG iterations per step after the first on the last system it solved; < 0: none seen.
  double multigrid_iterations = -1;
  long steps_per_system = 0;  // steps the last system served (weighed with defTolerance on); 0: none
  // Under kAuto, the last choice: the factor values its analysis projected (0: none) and whether
  // the cost model, not the memory, refused that factor.
  double factor_values = 0;
  bool multigrid_by_cost = false;
};

// The counts of one linear system's solves: the steps it served and multigrid's iterations.
// The steady count is the median over the steps after the first: the cold starts of a new system
// are the cost model's own term, and those after a gap in the engine's history (a step it was
// not run for) are no more typical of the steps to come.
struct SolveTally {
  long steps = 0;
  std::vector<long> steps_with;  // steps after the first by CG iterations (the last: that many or more)

  void add(int cg_iterations);
  // Takes back the last add(cg_iterations) (a step undone).
  void remove(int cg_iterations);
  // The history it leaves: the steps, and the median iterations per step if multigrid solved them.
  SolveHistory history(SolveHistory before, bool multigrid) const;
};

// CG iterations per step assumed where multigrid has not run: between a smooth motion's (a fixed
// skeleton or a steady drift takes one to one and a half) and those of velocities that change
// from step to step (up to about eleven), on the side of the factor at the sizes where both fit.
constexpr double kAssumedMultigridIterations = 2;

// The inputs of a choice: the system's unknowns and the history of the last one.
struct CostInputs {
  double unknowns = 0;
  double iterations = kAssumedMultigridIterations;  // per step
  double steps_per_system = 1;
  MultigridSmoother smoother = MultigridSmoother::kGaussSeidel;
};
CostInputs cost_inputs(double unknowns, const SolveHistory& history, const EngineSettings& settings);

// Seconds per step on the reference machine, set-up spread over inputs.steps_per_system.
double cholesky_step_cost(double factor_values, const CostInputs& inputs);
double multigrid_step_cost(const CostInputs& inputs);
// The factor (stored values) beyond which multigrid's step costs less than the factor's.
double break_even_factor_values(const CostInputs& inputs);

}  // namespace pfv
