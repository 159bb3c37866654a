// PFV's supernodal numeric factorisation (supernodal_numeric.hpp) against CHOLMOD's on the same
// symbolic factor: the same solutions to round-off, and the same first non-positive pivot.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "pfv/linalg/cholmod_solver.hpp"
#include "test_matrices.hpp"

using namespace pfv;

namespace {

std::vector<double> solve(const SymmetricMatrix& g, Ordering ordering, bool cholmod_numeric) {
  CholmodSolver s;
  s.set_openmp_teams(cholmod_numeric);  // CHOLMOD's own numeric factorisation, with its teams
  s.factorize(g, ordering);
  std::vector<double> b(g.size()), x;
  for (int i = 0; i < g.size(); ++i) b[i] = std::sin(0.37 * i + 1);
  s.solve(b, x);
  return x;
}

std::string pivot_error(const SymmetricMatrix& g, bool cholmod_numeric) {
  CholmodSolver s;
  s.set_openmp_teams(cholmod_numeric);
  try {
    s.factorize(g, Ordering::kAmd);
  } catch (const std::domain_error& e) {
    EXPECT_FALSE(s.ready());
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SupernodalNumeric, SolvesAsCholmodsFactorisation) {
  const SymmetricMatrix g = *test::grid_laplacian(20, 18, 16);
  ASSERT_GT(g.size(), 5000);
  for (Ordering ordering : {Ordering::kAmd, Ordering::kMetis}) {
    const auto ours = solve(g, ordering, false), theirs = solve(g, ordering, true);
    ASSERT_EQ(ours.size(), theirs.size());
    double scale = 0, diff = 0;
    for (std::size_t i = 0; i < ours.size(); ++i) {
      scale = std::max(scale, std::abs(theirs[i]));
      diff = std::max(diff, std::abs(ours[i] - theirs[i]));
    }
    ASSERT_GT(scale, 0);
    EXPECT_LE(diff, 1e-12 * scale) << "ordering " << static_cast<int>(ordering);
  }
}

TEST(SupernodalNumeric, ReportsTheFirstNonPositivePivotAsCholmodDoes) {
  SymmetricMatrix g = *test::random_spd(2000, 12);
  // Unknown n/2's diagonal (the last stored entry of its column of the upper triangle) made
  // negative: G is no longer positive definite.
  const int u = g.size() / 2;
  const int diagonal = g.col_start[u + 1] - 1;
  ASSERT_EQ(g.row[diagonal], u);
  g.value[diagonal] = -g.value[diagonal];
  const std::string ours = pivot_error(g, false), theirs = pivot_error(g, true);
  EXPECT_NE(ours.find("not positive definite"), std::string::npos) << ours;
  EXPECT_EQ(ours, theirs);
}
