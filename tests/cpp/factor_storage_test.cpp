// The storage of the factor's values outlives the factor: a solver factorising again reuses it,
// and what is left in it from an earlier factor (double or 32-bit) changes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/refinement.hpp"
#include "test_matrices.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

std::vector<double> rhs(int n) {
  std::vector<double> b(n);
  for (int i = 0; i < n; ++i) b[i] = std::sin(0.37 * i + 1);
  return b;
}

std::vector<double> solve(CholmodSolver& s, const std::vector<double>& b) {
  std::vector<double> x;
  s.solve(b, x);
  return x;
}

}  // namespace

TEST(FactorStorage, ReusedStorageGivesTheFreshSolution) {
  const SymmetricMatrix small = *test::grid_laplacian(10, 9, 8), large = *test::grid_laplacian(14, 13, 12);
  ASSERT_LT(small.size(), large.size());
  const auto b = rhs(small.size());

  CholmodSolver fresh;
  fresh.factorize(small, Ordering::kAmd);
  const auto expected = solve(fresh, b);

  CholmodSolver reused;
  EXPECT_EQ(reused.value_capacity(), 0u);
  reused.factorize(large, Ordering::kAmd, FactorPrecision::kScaled32, {}, 0);  // leaves 32-bit entries behind
  ASSERT_TRUE(reused.reduced_precision());
  const std::size_t capacity = reused.value_capacity();
  EXPECT_GT(capacity, 0u);
  reused.release();
  EXPECT_FALSE(reused.ready());
  EXPECT_EQ(reused.value_capacity(), capacity);  // kept

  reused.factorize(small, Ordering::kAmd);
  EXPECT_EQ(reused.value_capacity(), capacity);  // fits: no new block
  EXPECT_EQ(solve(reused, b), expected);         // to the bit

  // Growing: the larger factor needs more than the small one left.
  CholmodSolver grown;
  grown.factorize(small, Ordering::kAmd);
  const std::size_t before = grown.value_capacity();
  grown.release();
  grown.factorize(large, Ordering::kAmd);
  EXPECT_GT(grown.value_capacity(), before);
  CholmodSolver reference;
  reference.factorize(large, Ordering::kAmd);
  const auto bl = rhs(large.size());
  EXPECT_EQ(solve(grown, bl), solve(reference, bl));
}

TEST(FactorStorage, RemeshesFactoriseInTheStorageOfThePreviousFactor) {
  auto p = test::random_packing(600, 11, 0.02, 0.035);
  FlowEngine e = test::permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1e-3);
  const std::size_t capacity = e.cholmod().value_capacity();
  ASSERT_GT(capacity, 0u);
  for (int k = 0; k < 3; ++k) {
    for (auto& c : p.centre) c += Vec3(1e-6, -1e-6, 0);
    e.request_remesh();
    e.step(p.centre, p.radius, p.walls, 1e-3);
    EXPECT_EQ(e.remesh_count(), k + 2);
    EXPECT_EQ(e.cholmod().value_capacity(), capacity);  // the same block (grown only if it no longer fits)
    ASSERT_TRUE(e.cholmod().ready());
  }
  // And the pressures are those of a new engine's first factor (in fresh storage), on the same
  // positions (unmoved since the last step: no volume change in either) and the same ordering.
  FlowEngine fresh = test::permeameter(1);
  fresh.settings.reuse_ordering = false;
  e.settings.reuse_ordering = false;
  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1e-3);
  fresh.step(p.centre, p.radius, p.walls, 1e-3);
  ASSERT_EQ(e.pressure().size(), fresh.pressure().size());
  for (std::size_t c = 0; c < e.pressure().size(); ++c) EXPECT_EQ(e.pressure()[c], fresh.pressure()[c]) << c;
}

// A factor beyond what CHOLMOD's 32-bit indices address (2^31 - 1 values; about a million
// spheres) is refused like one beyond the budget, whatever the memory: the solver is left as
// after release() and factorises afterwards. The range is lowered here so that a small factor
// exceeds it; CHOLMOD's own refusal of a larger one (CHOLMOD_TOO_LARGE, mapped to the same
// exception) needs a million spheres: `bench/first_step_stages.py 1e6 --solvers=auto`.
TEST(FactorStorage, AFactorBeyondTheIndexRangeIsRefused) {
  const auto g = test::grid_laplacian(12, 11, 10);
  CholeskySolver solver;
  SolverOptions options;
  options.factor.index_range = 1000;  // in place of 2^31 - 1: this system's factor exceeds it
  try {
    solver.setup(g, options);
    FAIL() << "a factor beyond the index range was accepted";
  } catch (const FactorTooLarge& e) {
    EXPECT_EQ(e.why, FactorLimit::kIndexRange);
    EXPECT_GT(e.entries, 1000);
    EXPECT_EQ(e.limit, 1000);
    EXPECT_NE(std::string(e.what()).find("32-bit indices"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(solver.ready());
  solver.setup(g, SolverOptions{});
  ASSERT_TRUE(solver.ready());
  std::vector<double> b(g->size(), 1.0), x;
  solver.solve(b, x, SolveControl{});
  std::vector<double> r;
  residual(*g, MatrixRows{}, b, x, r);
  for (double v : r) EXPECT_LT(std::abs(v), 1e-9);
}
