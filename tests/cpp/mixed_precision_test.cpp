// A single-precision factor inside iterative refinement gives the double solve's pressures,
// and falls back to double when the system is beyond float.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "flow_engine.hpp"
#include "refinement.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// A chain of n cells between a Dirichlet cell (p = 0, folded into the diagonal) and a closed
// end, whose conductances fall geometrically over 'decades': cond(G) ~ 10^decades.
PressureSystem graded_chain(int n, double decades, double scale = 1) {
  PressureSystem s;
  s.unknown_cell.resize(n);
  s.col_start.push_back(0);
  const auto k = [&](int i) { return scale * std::pow(10.0, -decades * i / n); };  // throat i-1 -> i
  for (int j = 0; j < n; ++j) {
    s.unknown_cell[j] = j;
    if (j > 0) {
      s.row.push_back(j - 1);
      s.value.push_back(-k(j));
    }
    s.row.push_back(j);
    s.value.push_back(k(j) + (j + 1 < n ? k(j + 1) : 0.0));
    s.col_start.push_back(static_cast<int>(s.row.size()));
  }
  return s;
}

// G^-1 b with CHOLMOD's double factor: the reference.
std::vector<double> double_solve(const PressureSystem& s, const std::vector<double>& b) {
  CholmodSolver exact;
  exact.factorize(s, Ordering::kAmd);
  std::vector<double> x;
  exact.solve(b, x);
  return x;
}

}  // namespace

TEST(MixedPrecision, MatchesTheDoubleSolveOverMovingSteps) {
  const auto p = test::random_packing(600, 71, 0.02, 0.035);
  FlowEngine exact = test::permeameter(1), mixed = test::permeameter(1);
  exact.settings.mixed_precision = false;
  mixed.settings.mixed_precision = true;
  std::vector<Vec3> x = p.centre;
  const double dt = 1e-3;
  for (int step = 0; step < 6; ++step) {
    for (std::size_t k = 0; k < x.size(); ++k)  // a slow, smooth squeeze along y: dV/dt != 0
      x[k].y() = 0.5 + (p.centre[k].y() - 0.5) * (1 - 2e-4 * step);
    exact.step(x, p.radius, p.walls, dt);
    mixed.step(x, p.radius, p.walls, dt);
    ASSERT_TRUE(mixed.cholmod().single_precision());
    const double scale = max_abs(exact.pressure());
    ASSERT_GT(scale, 0);
    for (std::size_t c = 0; c < exact.pressure().size(); ++c)
      ASSERT_NEAR(mixed.pressure()[c], exact.pressure()[c], 1e-9 * scale) << "step " << step << " cell " << c;
    if (step > 0) {
      EXPECT_LE(mixed.gs_iterations(), 2) << "refinement passes at step " << step;
    }
  }
  EXPECT_GT(mixed.refinement_contraction(), 0);
  EXPECT_LT(mixed.refinement_contraction(), 0.01);
  ASSERT_FALSE(exact.cholmod().single_precision());
  for (std::size_t v = 0; v < exact.forces().size(); ++v)
    EXPECT_LE((mixed.forces()[v] - exact.forces()[v]).norm(), 1e-8 * (exact.forces()[v].norm() + 1e-12));
}

TEST(MixedPrecision, ToleranceFollowsThePressureDifferencesNotTheirOffset) {
  // 1 Pa across the sample on top of 1e5 Pa: the forces depend on the 1 Pa, so the refined
  // pressures must match the double solve to the tolerance of the spread, not of 1e5.
  const auto p = test::random_packing(600, 71, 0.02, 0.035);
  FlowEngine exact = test::permeameter(1), mixed = test::permeameter(1);
  for (FlowEngine* e : {&exact, &mixed}) {
    e->bc.value[2] = 1e5 + 1;
    e->bc.value[3] = 1e5;
  }
  exact.settings.mixed_precision = false;
  mixed.settings.mixed_precision = true;
  std::vector<Vec3> x = p.centre;
  for (int step = 0; step < 3; ++step) {
    for (std::size_t k = 0; k < x.size(); ++k) x[k].y() = 0.5 + (p.centre[k].y() - 0.5) * (1 - 1e-6 * step);
    exact.step(x, p.radius, p.walls, 1e-3);
    mixed.step(x, p.radius, p.walls, 1e-3);
    ASSERT_TRUE(mixed.cholmod().single_precision());
    const auto [lo, hi] = std::minmax_element(exact.pressure().begin(), exact.pressure().end());
    const double spread = *hi - *lo;
    ASSERT_GT(spread, 0.5);
    for (std::size_t c = 0; c < exact.pressure().size(); ++c)
      // 5e-9: the double reference itself carries ~1e-9 Pa of round-off at 1e5 Pa; a tolerance
      // taken relative to max|p| leaves 3e-8 here.
      ASSERT_NEAR(mixed.pressure()[c], exact.pressure()[c], 5e-9 * spread) << "step " << step << " cell " << c;
  }
}

TEST(MixedPrecision, LongChainConvergesDespiteItsConditionNumber) {
  // cond(G) ~ 16 n^2 / pi^2 ~ 6e8, beyond float's 1 / 6e-8 - yet G is a graph Laplacian (an
  // M-matrix) whose rounded factor stays a componentwise-small perturbation: refinement still
  // contracts. The conductance matrices of the pore network are all of this kind.
  const PressureSystem s = graded_chain(20000, 0);
  std::vector<double> b(s.n_unknowns(), 0.0), x;
  b.back() = 1e-10;  // a flux injected at the closed end
  const std::vector<double> x_exact = double_solve(s, b);
  CholmodSolver single;
  single.factorize(s, Ordering::kAmd, FactorPrecision::kSingle);
  ASSERT_TRUE(single.single_precision());
  Refinement r;
  x.assign(b.size(), 0.0);
  ASSERT_TRUE(r.solve(s, single, b, x, 1e-10, 8));
  EXPECT_LT(r.contraction(), 0.5);
  const double scale = max_abs(x_exact);
  for (std::size_t i = 0; i < x.size(); ++i) ASSERT_NEAR(x[i], x_exact[i], 1e-9 * scale);
}

TEST(MixedPrecision, IllConditionedDenseSystemIsDetectedAndSolvedInDouble) {
  // Eigenvalues 1 ... 1e-15 along random directions. Rounding the factor L to float makes
  // I - M^-1 G similar to L^-1 dL + (L^-1 dL)', of norm ~ sqrt(cond) * 6e-8: here ~2, so the
  // passes do not contract and the caller refactorises in double. (At cond 1e10 rho is still
  // ~1e-3: graph Laplacians never get near this.)
  const int n = 30;
  std::mt19937 gen(5);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = normal(gen);
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(a).householderQ();
  Eigen::VectorXd lambda(n);
  for (int i = 0; i < n; ++i) lambda[i] = std::pow(10.0, -15.0 * i / (n - 1));
  const Eigen::MatrixXd g = q * lambda.asDiagonal() * q.transpose();
  PressureSystem s;
  s.unknown_cell.resize(n);
  s.col_start.push_back(0);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i <= j; ++i) {
      s.row.push_back(i);
      s.value.push_back(g(i, j));
    }
    s.col_start.push_back(static_cast<int>(s.row.size()));
  }
  std::vector<double> b(n), x(n, 0.0);
  for (int i = 0; i < n; ++i) b[i] = std::sin(1.0 + i);
  const std::vector<double> x_exact = double_solve(s, b);
  CholmodSolver single;
  single.factorize(s, Ordering::kAmd, FactorPrecision::kSingle);
  ASSERT_TRUE(single.single_precision());
  Refinement r;
  EXPECT_FALSE(r.solve(s, single, b, x, 1e-10, 8));
  single.promote_to_double(s);
  EXPECT_FALSE(single.single_precision());
  single.solve(b, x);
  for (int i = 0; i < n; ++i) EXPECT_EQ(x[i], x_exact[i]);  // the same double factor
}

TEST(MixedPrecision, WellConditionedChainConvergesFromAColdStart) {
  const PressureSystem s = graded_chain(50, 1);  // cond ~ 1e4
  std::vector<double> b(s.n_unknowns()), x(s.n_unknowns(), 0.0), r;
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = std::cos(0.1 * i);
  const std::vector<double> x_exact = double_solve(s, b);
  CholmodSolver single;
  single.factorize(s, Ordering::kAmd, FactorPrecision::kSingle);
  Refinement refine;
  ASSERT_TRUE(refine.solve(s, single, b, x, 1e-12, 8));
  EXPECT_GE(refine.passes(), 2);  // a float solve alone is not accurate to 1e-12
  const double scale = max_abs(x_exact);
  for (std::size_t i = 0; i < x.size(); ++i) ASSERT_NEAR(x[i], x_exact[i], 1e-11 * scale);
  residual(s, b, x, r);
  EXPECT_LE(max_abs(r), 1e-13 * max_abs(x) * 2);  // round-off level: |G| <= 2 max k = 2
}

TEST(MixedPrecision, FactorOutsideFloatRangeStaysDouble) {
  const PressureSystem s = graded_chain(100, 1, 1e80);  // factor entries ~1e40 > FLT_MAX
  CholmodSolver solver;
  solver.factorize(s, Ordering::kAmd, FactorPrecision::kSingle);
  EXPECT_FALSE(solver.single_precision());
  std::vector<double> b(s.n_unknowns(), 1e80), x, r;
  solver.solve(b, x);
  residual(s, b, x, r);
  EXPECT_LE(max_abs(r), 1e-10 * max_abs(b));
}
