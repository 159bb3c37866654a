#include "pfv/engine/solver_cost.hpp"

#include <algorithm>
#include <cmath>

namespace pfv {
namespace {

// Per-unit costs on the benchmark lattice (jittered cubic, about 6.8 cells per sphere), one
// thread: the 50 000- and 200 000-sphere systems (324 551 and 1.36 million unknowns, factors of
// 5.1e7 and 3.4e8 values) of doc/solvers.md and doc/scaling.md.
// A step with the factor: one substitution of the 32-bit factor and a refinement pass.
constexpr double kSubstitutionPerValue = 0.85e-9;
// The numeric factorisation grows faster than the factor: 2.53 s at 5.1e7 values, 30.6 s at
// 3.4e8, a power of 1.31 between them.
constexpr double kFactorSecondsAt = 2.53, kFactorValuesAt = 5.13e7, kFactorPower = 1.31;
// One CG iteration preconditioned by a symmetric Gauss-Seidel V-cycle, per unknown; the split
// sweeps read each level once per direction, the l1-Jacobi smoother once.
constexpr double kIterationPerUnknown = 1.0e-7;
constexpr double kSplitIteration = 0.7, kJacobiIteration = 0.65;
// A new system for multigrid: the hierarchy, the pressures carried over from the old mesh, and
// the iterations of its first solves (from the carried pressures, and the time-step guard's).
constexpr double kHierarchyPerUnknown = 2.4e-6;
constexpr double kIterationsPerNewSystem = 10;

constexpr double kNeverRemeshed = 1e6;  // steps a system serves with no remesh scheduled

double iteration_cost(const CostInputs& in) {
  const double scale = in.smoother == MultigridSmoother::kSplitGaussSeidel ? kSplitIteration
                       : in.smoother == MultigridSmoother::kJacobi         ? kJacobiIteration
                                                                           : 1.0;
  return scale * kIterationPerUnknown * in.unknowns;
}

constexpr int kCounted = 64;  // iterations counted apart; beyond, the factor wins at any size this counts for

}  // namespace

void SolveTally::add(int cg_iterations) {
  if (steps++ == 0) return;  // a cold start
  const auto k = static_cast<std::size_t>(std::clamp(cg_iterations, 0, kCounted));
  if (steps_with.size() <= k) steps_with.resize(k + 1, 0);
  ++steps_with[k];
}

void SolveTally::remove(int cg_iterations) {
  if (steps == 0 || --steps == 0) return;  // the cold start was not counted
  --steps_with[static_cast<std::size_t>(std::clamp(cg_iterations, 0, kCounted))];
  while (!steps_with.empty() && steps_with.back() == 0) steps_with.pop_back();  // as add() left it
}

SolveHistory SolveTally::history(SolveHistory before, bool multigrid) const {
  if (steps == 0) return before;  // never solved: nothing learnt
  before.steps_per_system = steps;
  if (multigrid && steps > 1) {
    long below = 0;
    for (std::size_t k = 0; k < steps_with.size(); ++k)
      if (2 * (below += steps_with[k]) >= steps - 1) {
        before.multigrid_iterations = static_cast<double>(k);
        break;
      }
  }
  return before;
}

CostInputs cost_inputs(double unknowns, const SolveHistory& history, const EngineSettings& settings) {
  CostInputs in;
  in.unknowns = unknowns;
  if (history.multigrid_iterations >= 0) in.iterations = std::max(1.0, history.multigrid_iterations);
  // The schedule says how long a system lives; with the strain criterion on, the steps the last
  // system served say it better. A remesh asked for by the caller (or a change of the boundary
  // conditions) ends a system early without saying anything about the next one.
  in.steps_per_system = settings.mesh_update_interval > 0 ? settings.mesh_update_interval : kNeverRemeshed;
  if (settings.def_tolerance > 0 && history.steps_per_system > 0)
    in.steps_per_system = std::min(in.steps_per_system, static_cast<double>(history.steps_per_system));
  in.steps_per_system = std::clamp(in.steps_per_system, 1.0, kNeverRemeshed);
  in.smoother = settings.multigrid_smoother;
  return in;
}

double cholesky_step_cost(double values, const CostInputs& in) {
  const double factorisation = kFactorSecondsAt * std::pow(values / kFactorValuesAt, kFactorPower);
  return kSubstitutionPerValue * values + factorisation / in.steps_per_system;
}

double multigrid_step_cost(const CostInputs& in) {
  const double per_system = kHierarchyPerUnknown * in.unknowns + kIterationsPerNewSystem * iteration_cost(in);
  return in.iterations * iteration_cost(in) + per_system / in.steps_per_system;
}

double break_even_factor_values(const CostInputs& in) {
  // cholesky_step_cost grows with the factor: bisect on its logarithm.
  const double target = multigrid_step_cost(in);
  double lo = 1, hi = 1e15;
  if (cholesky_step_cost(hi, in) <= target) return hi;
  for (int k = 0; k < 100 && hi > lo * (1 + 1e-9); ++k) {
    const double mid = std::sqrt(lo * hi);
    (cholesky_step_cost(mid, in) < target ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace pfv
