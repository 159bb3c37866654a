// What a pressure solver's setup reads besides G (PressureSolver::setup): each solver takes
// the options that concern it and ignores the others.
#pragma once
#include <limits>

#include "pfv/linalg/cholmod_solver.hpp"

namespace pfv {

// The Cholesky factor's (cholesky_solver.hpp).
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

// The smoother of the multigrid V-cycle (amg_solver.hpp): hypre's symmetric l1-Gauss-Seidel
// sweep pair on the way down and up; its l1-scaled Jacobi; or kSplitGaussSeidel, one forward
// Gauss-Seidel sweep on the way down and one backward sweep on the way up (the cycle stays
// symmetric, with half the sweeps of kGaussSeidel).
enum class MultigridSmoother { kGaussSeidel, kJacobi, kSplitGaussSeidel };

struct SolverOptions {
  FactorOptions factor;
  MultigridSmoother multigrid_smoother = MultigridSmoother::kGaussSeidel;
};

}  // namespace pfv
