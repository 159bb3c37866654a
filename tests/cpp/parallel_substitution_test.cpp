// PFV's substitution on the compacted supernodal factor solves G x = b, and its two-thread
// schedule gives the serial answer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "pfv/engine/flow_engine.hpp"
#include "pfv/linalg/refinement.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// |b - G x| relative to |G| |x|, the scale of round-off in the product.
double relative_residual(const SymmetricMatrix& s, const std::vector<double>& b, const std::vector<double>& x) {
  std::vector<double> r;
  residual(s, MatrixRows{}, b, x, r);
  const double g = max_abs(s.value) * 14;  // a cell has at most four throats; the row sum bounds |G|
  return max_abs(r) / (g * max_abs(x));
}

}  // namespace

TEST(ParallelSubstitution, SolvesTheSystemSeriallyAndOnTwoThreads) {
  for (bool single : {false, true}) {
    for (int n : {50, 600, 3000}) {
      const auto p = test::random_packing(n, 61, 0.02, 0.03);
      FlowEngine e = test::permeameter(1);
      e.settings.mixed_precision = single;
      e.settings.mixed_precision_min_entries = 0;
      e.step(p.centre, p.radius, p.walls, 1.0);
      auto& solver = const_cast<CholmodSolver&>(e.cholmod());
      ASSERT_EQ(solver.reduced_precision(), single);
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
      if (n == 3000) {
        EXPECT_GT(solver.shared_top_supernodes(), 0);  // and the root separator too
      }
      // Double: backward stable. 32-bit: the factor's unit, 2^-31 of each column's largest
      // entry, times the growth of the substitution.
      EXPECT_LT(relative_residual(*e.system().matrix, b, serial), single ? 1e-8 : 1e-13) << n;
      ASSERT_EQ(parallel.size(), serial.size());
      for (int i = 0; i < nu; ++i) ASSERT_EQ(parallel[i], serial[i]) << n;  // the same operations in the same order
    }
  }
}
