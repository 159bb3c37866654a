// The two-thread substitution gives CHOLMOD's serial answer.
#include <gtest/gtest.h>

#include <cmath>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "flow_engine.hpp"
#include "test_packings.hpp"

using namespace pfv;

TEST(ParallelSubstitution, MatchesCholmodSolve) {
  for (int n : {50, 600}) {
    const auto p = test::random_packing(n, 61, 0.02, 0.03);
    FlowEngine e = test::permeameter(1);
    e.settings.mixed_precision = false;  // the double factor: CHOLMOD's serial solve is the reference
    e.step(p.centre, p.radius, p.walls, 1.0);
    auto& solver = const_cast<CholmodSolver&>(e.cholmod());
    const int nu = e.system().n_unknowns();
    std::vector<double> b(nu), serial, parallel;
    for (int i = 0; i < nu; ++i) b[i] = std::sin(0.37 * i) + 0.1 * (i % 7);
    solver.solve_serial(b, serial);
#ifdef _OPENMP
    const int before = omp_get_max_threads();
    omp_set_num_threads(2);
#endif
    solver.solve(b, parallel);
#ifdef _OPENMP
    omp_set_num_threads(before);
#endif
    EXPECT_LT(solver.parallel_top_fraction(), 1.0);  // some work was split between threads
    double scale = 0;
    for (double v : serial) scale = std::max(scale, std::abs(v));
    ASSERT_EQ(parallel.size(), serial.size());
    for (int i = 0; i < nu; ++i) EXPECT_NEAR(parallel[i], serial[i], 1e-12 * scale);
  }
}
