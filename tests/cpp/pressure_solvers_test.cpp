// Every pressure solver through the seam the engine uses (PressureSolver::setup, then solve
// and apply_inverse), on matrices made here without a mesh (test_matrices.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "pfv/engine/solver_policy.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/gauss_seidel_solver.hpp"
#include "pfv/linalg/matrix_rows.hpp"
#include "pfv/linalg/pcg_solver.hpp"
#include "pfv/linalg/refinement.hpp"
#include "test_matrices.hpp"
#if PFV_WITH_HYPRE
#include "pfv/linalg/amg_solver.hpp"
#endif

namespace pfv {
namespace {

std::vector<double> right_hand_side(int n) {
  std::vector<double> b(n);
  for (int u = 0; u < n; ++u) b[u] = std::sin(0.3 * u) + (u % 7 == 0 ? 2.0 : 0.0);
  return b;
}

std::vector<double> exact(const SymmetricMatrix& g, const std::vector<double>& b) {
  CholmodSolver f;
  f.factorize(g, Ordering::kAmd);
  std::vector<double> x;
  f.solve(b, x);
  return x;
}

// max |x - y| relative to the spread of y.
double error(const std::vector<double>& x, const std::vector<double>& y) {
  double e = 0;
  for (std::size_t i = 0; i < x.size(); ++i) e = std::max(e, std::abs(x[i] - y[i]));
  const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
  return e / (*hi - *lo);
}

std::vector<std::unique_ptr<PressureSolver>> all_solvers() {
  std::vector<std::unique_ptr<PressureSolver>> s;
  s.push_back(std::make_unique<GaussSeidelSolver>());
  s.push_back(std::make_unique<PcgSolver>());
  s.push_back(std::make_unique<CholeskySolver>());
#if PFV_WITH_HYPRE
  s.push_back(std::make_unique<AmgSolver>());
#endif
  return s;
}

// Tight stopping rules, so that each solver's result can be held to the exact one.
SolveControl tight() {
  SolveControl c;
  c.tolerance = 1e-12;
  c.refinement_tolerance = 1e-12;
  return c;
}

TEST(PressureSolvers, EverySolverSolvesTheMatrixItWasSetUpWith) {
  for (const auto& g : {test::grid_laplacian(12, 10, 9), test::random_spd(3000, 7)}) {
    const std::vector<double> b = right_hand_side(g->size()), reference = exact(*g, b);
    for (auto& solver : all_solvers()) {
      const std::string name(to_string(solver->kind()));
      solver->setup(g, SolverOptions{});
      ASSERT_TRUE(solver->ready()) << name;
      std::vector<double> x(g->size(), 0.0);
      const SolveStats stats = solver->solve(b, x, tight());
      EXPECT_TRUE(stats.converged) << name;
      EXPECT_LT(error(x, reference), 1e-8) << name;
      std::vector<double> y;
      solver->apply_inverse(b, y, tight());
      EXPECT_LT(error(y, reference), 1e-8) << name;
    }
  }
}

TEST(PressureSolvers, ASolverKeepsItsMatrixAfterTheCallerLetsGo) {
  auto g = test::random_spd(2000, 3);
  const std::vector<double> b = right_hand_side(g->size()), reference = exact(*g, b);
  for (auto& solver : all_solvers()) {
    solver->setup(std::make_shared<const SymmetricMatrix>(*g), SolverOptions{});  // the only owner
    std::vector<double> x(g->size(), 0.0);
    solver->solve(b, x, tight());
    EXPECT_LT(error(x, reference), 1e-8) << to_string(solver->kind());
  }
}

TEST(PressureSolvers, A32BitFactorRefinesToTheDoubleSolution) {
  const auto g = test::grid_laplacian(16, 14, 12);
  const std::vector<double> b = right_hand_side(g->size()), reference = exact(*g, b);
  CholeskySolver solver;
  SolverOptions options;
  options.factor.precision = FactorPrecision::kScaled32;
  solver.setup(g, options);
  ASSERT_TRUE(solver.factor().reduced_precision());
  EXPECT_EQ(solver.rows().width, 6);  // the 7-point stencil's neighbours
  std::vector<double> x(g->size(), 0.0);
  const SolveStats stats = solver.solve(b, x, SolveControl{});
  EXPECT_GE(stats.refinement_passes, 1);
  EXPECT_LT(error(x, reference), 1e-9);
}

TEST(PressureSolvers, RowsAndColumnsGiveTheSameResidual) {
  const auto g = test::random_spd(1500, 11);
  const MatrixRows rows = index_rows(*g);
  EXPECT_LE(rows.width, 4);
  const std::vector<double> b = right_hand_side(g->size());
  std::vector<double> x(g->size()), by_rows, by_columns;
  for (int u = 0; u < g->size(); ++u) x[u] = std::cos(0.7 * u);
  residual(*g, rows, b, x, by_rows);
  residual(*g, MatrixRows{}, b, x, by_columns);
  for (int u = 0; u < g->size(); ++u) EXPECT_NEAR(by_rows[u], by_columns[u], 1e-12 * (1 + std::abs(b[u]))) << u;
}

TEST(PressureSolvers, MultigridIsThereOnlyInABuildWithHypre) {
  EXPECT_EQ(solver_unavailable(SolverKind::kMultigrid).empty(), PFV_WITH_HYPRE != 0);
  if (!PFV_WITH_HYPRE) {
    EXPECT_NE(solver_unavailable(SolverKind::kMultigrid).find("without hypre"), std::string::npos);
  }
  for (SolverKind k :
       {SolverKind::kGaussSeidel, SolverKind::kConjugateGradient, SolverKind::kCholesky, SolverKind::kAuto}) {
    EXPECT_TRUE(solver_unavailable(k).empty()) << to_string(k);
  }
}

}  // namespace
}  // namespace pfv
