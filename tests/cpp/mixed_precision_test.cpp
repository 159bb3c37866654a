// A 32-bit factor (integers scaled per column) inside iterative refinement gives the double
// solve's pressures to the refinement tolerance, and falls back to double when the system is
// beyond it.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/refinement.hpp"
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
SymmetricMatrix graded_chain(int n, double decades, double scale = 1) {
  SymmetricMatrix s;
  s.col_start.push_back(0);
  const auto k = [&](int i) { return scale * std::pow(10.0, -decades * i / n); };  // throat i-1 -> i
  for (int j = 0; j < n; ++j) {
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
std::vector<double> double_solve(const SymmetricMatrix& s, const std::vector<double>& b) {
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
  mixed.settings.mixed_precision_min_entries = 0;  // small systems: 32 bits all the same
  std::vector<Vec3> x = p.centre;
  const double dt = 1e-3;
  for (int step = 0; step < 6; ++step) {
    for (std::size_t k = 0; k < x.size(); ++k)  // a slow, smooth squeeze along y: dV/dt != 0
      x[k].y() = 0.5 + (p.centre[k].y() - 0.5) * (1 - 2e-4 * step * (1 + 0.1 * step));
    exact.step(x, p.radius, p.walls, dt);
    mixed.step(x, p.radius, p.walls, dt);
    ASSERT_TRUE(mixed.cholmod().reduced_precision());
    const auto [lo, hi] = std::minmax_element(exact.pressure().begin(), exact.pressure().end());
    const double spread = *hi - *lo;
    ASSERT_GT(spread, 0);
    // The stopping rule's promise: within refinement_tolerance of the spread.
    for (std::size_t c = 0; c < exact.pressure().size(); ++c)
      ASSERT_NEAR(mixed.pressure()[c], exact.pressure()[c], mixed.settings.refinement_tolerance * spread)
          << "step " << step << " cell " << c;
    // Step 1 is the first with a volume change (a jump of the pressures) and step 2 extrapolates
    // that jump; from then on the start is extrapolated from a smooth history: one pass.
    if (step >= 3) {
      EXPECT_EQ(mixed.last_solve().refinement_passes, 1) << "refinement passes at step " << step;
    } else if (step > 0) {
      EXPECT_LE(mixed.last_solve().refinement_passes, 2) << "refinement passes at step " << step;
    }
  }
  // Far below float's 2.5e-7 on such systems; the estimate includes a safety factor of 4.
  EXPECT_GT(refinement_contraction(mixed), 0);
  EXPECT_LT(refinement_contraction(mixed), 1e-6);
  ASSERT_FALSE(exact.cholmod().reduced_precision());
  for (std::size_t v = 0; v < exact.forces().size(); ++v)
    EXPECT_LE((mixed.forces()[v] - exact.forces()[v]).norm(), 1e-9 * (exact.forces()[v].norm() + 1e-12));
}

TEST(MixedPrecision, ToleranceFollowsThePressureDifferencesNotTheirOffset) {
  // 1 Pa across the sample on top of 1e5 Pa: the forces depend on the 1 Pa, so the refined
  // pressures must be as accurate as the double solve up to the tolerance of the spread, not of
  // 1e5 (a tolerance relative to max|p| would allow 1e-5 Pa here). The exact pressures are
  // 1e5 + q, q the pressures of the same system with boundary values 1 and 0 (G's rows sum to
  // zero with their Dirichlet couplings), which a double solve gets to ~1e-16 Pa; at 1e5 Pa the
  // double solve itself is only accurate to its round-off there, measured as 'floor'.
  const auto p = test::random_packing(600, 71, 0.02, 0.035);
  FlowEngine exact = test::permeameter(1), mixed = test::permeameter(1), offset_free = test::permeameter(1);
  for (FlowEngine* e : {&exact, &mixed}) {
    e->bc.value[2] = 1e5 + 1;
    e->bc.value[3] = 1e5;
  }
  exact.settings.mixed_precision = offset_free.settings.mixed_precision = false;
  mixed.settings.mixed_precision = true;
  mixed.settings.mixed_precision_min_entries = 0;  // small systems: 32 bits all the same
  std::vector<Vec3> x = p.centre;
  for (int step = 0; step < 3; ++step) {
    for (std::size_t k = 0; k < x.size(); ++k) x[k].y() = 0.5 + (p.centre[k].y() - 0.5) * (1 - 1e-6 * step);
    for (FlowEngine* e : {&exact, &mixed, &offset_free}) e->step(x, p.radius, p.walls, 1e-3);
    ASSERT_TRUE(mixed.cholmod().reduced_precision());
    const auto [lo, hi] = std::minmax_element(exact.pressure().begin(), exact.pressure().end());
    const double spread = *hi - *lo;
    ASSERT_GT(spread, 0.5);
    double floor = 0;
    for (std::size_t c = 0; c < exact.pressure().size(); ++c)
      floor = std::max(floor, std::abs(exact.pressure()[c] - (1e5 + offset_free.pressure()[c])));
    EXPECT_LT(floor, 1e-7 * spread) << "the double reference itself at 1e5 Pa";
    // The mixed solve's residual is computed in double at 1e5 Pa too, so its own round-off is of
    // the size of the double solve's (measured 0.5-1.3 x floor over the steps and builds), on top
    // of the refinement's tolerance; an offset-relative tolerance would allow 1e-5 Pa instead.
    const double bound = 2 * floor + 10 * mixed.settings.refinement_tolerance * spread;
    for (std::size_t c = 0; c < exact.pressure().size(); ++c)
      ASSERT_NEAR(mixed.pressure()[c], 1e5 + offset_free.pressure()[c], bound)
          << "step " << step << " cell " << c << ", double round-off " << floor;
  }
}

TEST(MixedPrecision, LongChainConvergesDespiteItsConditionNumber) {
  // cond(G) ~ 16 n^2 / pi^2 ~ 6e8, close to the 2^31 steps of the 32-bit columns - yet G is a
  // graph Laplacian (an M-matrix) whose stored factor stays a small perturbation of each
  // column: refinement still contracts. The conductance matrices of the pore network are all
  // of this kind.
  const SymmetricMatrix s = graded_chain(20000, 0);
  std::vector<double> b(s.size(), 0.0), x;
  b.back() = 1e-10;  // a flux injected at the closed end
  const std::vector<double> x_exact = double_solve(s, b);
  CholmodSolver single;
  single.factorize(s, Ordering::kAmd, FactorPrecision::kScaled32);
  ASSERT_TRUE(single.reduced_precision());
  Refinement r;
  x.assign(b.size(), 0.0);
  ASSERT_TRUE(r.solve(s, MatrixRows{}, single, b, x, 1e-10, 8));
  EXPECT_LT(r.contraction(), 0.5);
  const double scale = max_abs(x_exact);
  for (std::size_t i = 0; i < x.size(); ++i) ASSERT_NEAR(x[i], x_exact[i], 1e-9 * scale);
}

TEST(MixedPrecision, IllConditionedDenseSystemIsDetectedAndSolvedInDouble) {
  // Eigenvalues 1 ... 1e-15 along random directions. Storing the factor L with 2^-31 of each
  // column's largest entry as its unit makes I - M^-1 G similar to L^-1 dL + (L^-1 dL)', of
  // norm up to ~ cond * 5e-10 for such a dense L: here the passes do not contract and the
  // caller refactorises in double. (Graph Laplacians never get near this.)
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
  SymmetricMatrix s;
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
  single.factorize(s, Ordering::kAmd, FactorPrecision::kScaled32);
  ASSERT_TRUE(single.reduced_precision());
  Refinement r;
  EXPECT_FALSE(r.solve(s, MatrixRows{}, single, b, x, 1e-10, 8));
  single.promote_to_double(s);
  EXPECT_FALSE(single.reduced_precision());
  single.solve(b, x);
  for (int i = 0; i < n; ++i) EXPECT_EQ(x[i], x_exact[i]);  // the same double factor
}

TEST(MixedPrecision, WellConditionedChainConvergesFromAColdStart) {
  const SymmetricMatrix s = graded_chain(50, 1);  // cond ~ 1e4
  std::vector<double> b(s.size()), x(s.size(), 0.0), r;
  for (std::size_t i = 0; i < b.size(); ++i) b[i] = std::cos(0.1 * i);
  const std::vector<double> x_exact = double_solve(s, b);
  CholmodSolver single;
  single.factorize(s, Ordering::kAmd, FactorPrecision::kScaled32);
  Refinement refine;
  ASSERT_TRUE(refine.solve(s, MatrixRows{}, single, b, x, 1e-12, 8));
  EXPECT_GE(refine.passes(), 2);  // one 32-bit solve alone is not accurate to 1e-12
  const double scale = max_abs(x_exact);
  for (std::size_t i = 0; i < x.size(); ++i) ASSERT_NEAR(x[i], x_exact[i], 1e-11 * scale);
  residual(s, MatrixRows{}, b, x, r);
  EXPECT_LE(max_abs(r), 1e-13 * max_abs(x) * 2);  // round-off level: |G| <= 2 max k = 2
}

TEST(MixedPrecision, FactorOfAnyMagnitudeKeepsItsPrecision) {
  // Each column carries its own double scale: conductances of 1e80 or 1e-80 (factor entries
  // 1e40, 1e-40, outside float's range) lose nothing to the 32-bit format.
  for (double scale : {1e80, 1e-80}) {
    const SymmetricMatrix s = graded_chain(100, 1, scale);
    CholmodSolver solver;
    solver.factorize(s, Ordering::kAmd, FactorPrecision::kScaled32);
    EXPECT_TRUE(solver.reduced_precision()) << scale;
    std::vector<double> b(s.size(), scale), x(s.size(), 0.0);
    const std::vector<double> x_exact = double_solve(s, b);
    Refinement refine;
    ASSERT_TRUE(refine.solve(s, MatrixRows{}, solver, b, x, 1e-12, 8)) << scale;
    EXPECT_LT(refine.contraction(), 1e-6) << scale;
    const double size = max_abs(x_exact);
    for (std::size_t i = 0; i < x.size(); ++i) ASSERT_NEAR(x[i], x_exact[i], 1e-11 * size) << scale;
  }
}

TEST(MixedPrecision, OneSubstitutionIsAccurateToTheFormat) {
  // Without refinement: the 32-bit factor's solve, against the double one on the same system.
  // Its error is the contraction times the solution, about 1e-8 here (float entries: 3e-7).
  const auto p = test::random_packing(3000, 12, 0.02, 0.03);
  FlowEngine exact = test::permeameter(1), mixed = test::permeameter(1);
  exact.settings.mixed_precision = false;
  mixed.settings.mixed_precision = true;
  mixed.settings.mixed_precision_min_entries = 0;  // whatever the size
  exact.step(p.centre, p.radius, p.walls, 1.0);
  mixed.step(p.centre, p.radius, p.walls, 1.0);
  ASSERT_TRUE(mixed.cholmod().reduced_precision());
  const int nu = exact.system().n_unknowns();
  std::vector<double> b(nu), x64, x32;
  for (int i = 0; i < nu; ++i) b[i] = std::sin(0.37 * i) + 0.1 * (i % 7);
  const_cast<CholmodSolver&>(exact.cholmod()).solve(b, x64);
  const_cast<CholmodSolver&>(mixed.cholmod()).solve(b, x32);
  double error = 0;
  for (int i = 0; i < nu; ++i) error = std::max(error, std::abs(x32[i] - x64[i]));
  EXPECT_LT(error, 1e-7 * max_abs(x64));
  EXPECT_GT(error, 0);  // it is a different factor
}

TEST(MixedPrecision, OnByDefaultForLargeFactorsOnly) {
  const auto p = test::random_packing(600, 71, 0.02, 0.035);
  FlowEngine e = test::permeameter(1);
  ASSERT_TRUE(e.settings.mixed_precision);
  e.step(p.centre, p.radius, p.walls, 1e-3);
  EXPECT_FALSE(e.cholmod().reduced_precision());  // a few 1e4 entries: below the default 2e6
  const std::vector<double> p_double = e.pressure();
  e.settings.mixed_precision_min_entries = 0;  // a changed setting rebuilds the factor
  e.step(p.centre, p.radius, p.walls, 1e-3);
  EXPECT_TRUE(e.cholmod().reduced_precision());
  const auto [lo, hi] = std::minmax_element(p_double.begin(), p_double.end());
  for (std::size_t c = 0; c < p_double.size(); ++c)
    ASSERT_NEAR(e.pressure()[c], p_double[c], e.settings.refinement_tolerance * (*hi - *lo));
  e.settings.mixed_precision = false;
  e.step(p.centre, p.radius, p.walls, 1e-3);
  EXPECT_FALSE(e.cholmod().reduced_precision());
}

TEST(MixedPrecision, ContractionCarriesOverRemeshes) {
  // A new mesh starts from the largest contraction of the earlier ones (its cold first solve
  // raises it if a pass contracts less): the estimate never falls, and the pressures still
  // meet the tolerance.
  const auto p = test::random_packing(600, 71, 0.02, 0.035);
  FlowEngine exact = test::permeameter(1), mixed = test::permeameter(1);
  exact.settings.mixed_precision = false;
  mixed.settings.mixed_precision_min_entries = 0;
  std::vector<Vec3> x = p.centre;
  double previous = 0;
  for (int step = 0; step < 4; ++step) {
    for (std::size_t k = 0; k < x.size(); ++k) x[k].y() = 0.5 + (p.centre[k].y() - 0.5) * (1 - 1e-3 * step);
    if (step > 0) {
      exact.request_remesh();
      mixed.request_remesh();
    }
    exact.step(x, p.radius, p.walls, 1e-3);
    mixed.step(x, p.radius, p.walls, 1e-3);
    ASSERT_TRUE(mixed.cholmod().reduced_precision());
    EXPECT_GE(refinement_contraction(mixed), previous) << "remesh " << step;
    previous = refinement_contraction(mixed);
    const auto [lo, hi] = std::minmax_element(exact.pressure().begin(), exact.pressure().end());
    for (std::size_t c = 0; c < exact.pressure().size(); ++c)
      ASSERT_NEAR(mixed.pressure()[c], exact.pressure()[c], mixed.settings.refinement_tolerance * (*hi - *lo))
          << "remesh " << step << " cell " << c;
  }
  EXPECT_EQ(mixed.remesh_count(), 4);
}

TEST(MixedPrecision, ResidualByRowsEqualsResidualByColumns) {
  // The refinement's residual reads G by rows (index_rows); the upper triangle by column is
  // the reference. Rows of width 4 (an assembled pore network) and of another width.
  const auto p = test::random_packing(400, 5, 0.02, 0.035);
  FlowEngine e = test::permeameter(1), exact = test::permeameter(1);
  e.settings.mixed_precision_min_entries = 0;  // a 32-bit factor: the engine indexes the rows
  exact.settings.mixed_precision = false;      // a double factor: no refinement, no rows
  e.step(p.centre, p.radius, p.walls, 1.0);
  exact.step(p.centre, p.radius, p.walls, 1.0);
  ASSERT_TRUE(e.cholmod().reduced_precision());
  EXPECT_TRUE(exact.cholesky()->rows().empty());
  const SymmetricMatrix chain = graded_chain(60, 2);
  const MatrixRows chain_rows = index_rows(chain);
  const std::pair<const SymmetricMatrix*, const MatrixRows*> cases[] = {
      {e.system().matrix.get(), &e.cholesky()->rows()}, {&chain, &chain_rows}};
  for (const auto& [s, rows] : cases) {
    const int n = s->size();
    ASSERT_EQ(static_cast<int>(rows->diagonal.size()), n);
    EXPECT_EQ(rows->width, s == &chain ? 2 : 4);
    std::vector<double> b(n), x(n), r_rows, r_columns;
    for (int i = 0; i < n; ++i) {
      b[i] = std::sin(0.7 * i);
      x[i] = std::cos(0.3 * i + 1);
    }
    residual(*s, *rows, b, x, r_rows);
    residual(*s, MatrixRows{}, b, x, r_columns);
    ASSERT_EQ(r_rows.size(), r_columns.size());
    double g_x = 0;  // the size of the terms summed: max |G| |x|
    for (double v : s->value) g_x = std::max(g_x, std::abs(v));
    g_x *= max_abs(x);
    double diff = 0;
    for (int i = 0; i < n; ++i) diff = std::max(diff, std::abs(r_rows[i] - r_columns[i]));
    EXPECT_LE(diff, 1e-14 * 5 * g_x);        // five terms per row, each rounded once
    EXPECT_GT(max_abs(r_rows), 1e-3 * g_x);  // not a vanishing residual
  }
}
