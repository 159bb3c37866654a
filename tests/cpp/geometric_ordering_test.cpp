// The geometric nested dissection (geometric_ordering.hpp): a permutation of the unknowns, a
// factor about as small as METIS's and far smaller than AMD's, the same pressures, carried over
// at remesh and computed afresh (not by METIS) when the carried order fills too much; the same
// order whatever the number of threads splitting the parts.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/linalg/geometric_ordering.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

FlowEngine solved(const test::TestPacking& p, Ordering ordering) {
  FlowEngine e = test::permeameter(1);
  e.settings.ordering = ordering;
  e.step(p.centre, p.radius, p.walls, 1.0);
  return e;
}

std::vector<std::array<double, 3>> power_centres(const FlowEngine& e) {
  const PressureSystem& s = e.system();
  std::vector<std::array<double, 3>> point(s.n_unknowns());
  for (int u = 0; u < s.n_unknowns(); ++u) {
    const Vec3& c = e.cells().power_centre[s.unknown_cell[u]];
    point[u] = {c[0], c[1], c[2]};
  }
  return point;
}

bool is_permutation_of_unknowns(std::vector<int> perm, int n) {
  std::sort(perm.begin(), perm.end());
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  return perm == all;
}

}  // namespace

TEST(GeometricOrdering, IsAPermutationOfTheUnknowns) {
  const FlowEngine e = solved(test::random_packing(600, 31), Ordering::kAuto);
  const int n = e.system().n_unknowns();
  ASSERT_GT(n, 2000);  // several levels of dissection at the default leaf size
  EXPECT_TRUE(is_permutation_of_unknowns(geometric_ordering(*e.system().matrix, power_centres(e)), n));
  GeometricOrderingOptions tiny;
  tiny.leaf_size = 2;  // dissected down to pairs: every band and flow degenerate case is met
  EXPECT_TRUE(is_permutation_of_unknowns(geometric_ordering(*e.system().matrix, power_centres(e), tiny), n));
}

TEST(GeometricOrdering, TheSameOrderOnAnyNumberOfThreads) {
  // Parts whose subtrees are split in parallel touch disjoint entries of the shared arrays:
  // the order must not depend on which thread splits which part, or when.
  const FlowEngine e = solved(test::random_packing(600, 34), Ordering::kAuto);
  const auto point = power_centres(e);
  GeometricOrderingOptions tiny;
  tiny.leaf_size = 2;
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::vector<int> serial = geometric_ordering(*e.system().matrix, point),
                         serial_tiny = geometric_ordering(*e.system().matrix, point, tiny);
  for (int t : {2, 3, 4}) {
    omp_set_num_threads(t);
    EXPECT_EQ(geometric_ordering(*e.system().matrix, point), serial) << t << " threads";
    EXPECT_EQ(geometric_ordering(*e.system().matrix, point, tiny), serial_tiny) << t << " threads";
  }
  omp_set_num_threads(threads);
}

TEST(GeometricOrdering, CoincidentPointsStillGiveAPermutation) {
  // No plane separates anything: each split still halves the part by rank, and ends.
  const FlowEngine e = solved(test::random_packing(200, 32), Ordering::kAuto);
  const std::vector<std::array<double, 3>> same(e.system().n_unknowns(), {0.5, 0.5, 0.5});
  EXPECT_TRUE(is_permutation_of_unknowns(geometric_ordering(*e.system().matrix, same), e.system().n_unknowns()));
}

TEST(GeometricOrdering, RejectsPointsThatDoNotMatchTheUnknowns) {
  const FlowEngine e = solved(test::random_packing(100, 33), Ordering::kAuto);
  auto point = power_centres(e);
  point.pop_back();
  EXPECT_THROW(geometric_ordering(*e.system().matrix, point), std::invalid_argument);
  point = power_centres(e);
  point[3][1] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(geometric_ordering(*e.system().matrix, point), std::invalid_argument);
}

TEST(GeometricOrdering, FillsAboutAsLittleAsMetisAndFarLessThanAmd) {
  const auto p = test::random_packing(4000, 13, 0.02, 0.03);
  const FlowEngine geometric = solved(p, Ordering::kGeometric), metis = solved(p, Ordering::kMetis),
                   amd = solved(p, Ordering::kAmd);
  ASSERT_GT(geometric.system().n_unknowns(), 20000);
  EXPECT_FALSE(geometric.cholmod().metis_used());
  EXPECT_FALSE(geometric.cholmod().ordering_given());  // a fresh order, not a carried one
  const double g = geometric.cholmod().factor_nonzeros();
  EXPECT_LT(g, 1.05 * metis.cholmod().factor_nonzeros());
  EXPECT_LT(g, 0.75 * amd.cholmod().factor_nonzeros());
  // The same system solved: the order changes the round-off only.
  double range = 0, difference = 0;
  for (std::size_t c = 0; c < metis.pressure().size(); ++c) {
    range = std::max(range, std::abs(metis.pressure()[c]));
    difference = std::max(difference, std::abs(geometric.pressure()[c] - metis.pressure()[c]));
  }
  EXPECT_LE(difference, 1e-10 * range);
}

TEST(GeometricOrdering, CarriedOverAtRemeshAndComputedAfreshWhenItFillsTooMuch) {
  const auto p = test::random_packing(800, 34, 0.02, 0.03);
  FlowEngine e = solved(p, Ordering::kGeometric);
  const double fill = e.cholmod().fill();
  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_TRUE(e.cholmod().ordering_given());
  EXPECT_EQ(e.cholmod().fill(), fill);
  // Large motion and no growth allowed: the carried order is refused, and the order computed
  // instead is the geometric one of the new mesh (what a fresh engine finds), not METIS's.
  test::TestPacking moved = p;
  std::mt19937 gen(35);
  std::uniform_real_distribution<double> u(-0.006, 0.006);
  for (Vec3& c : moved.centre) c += Vec3(u(gen), u(gen), u(gen));
  e.settings.max_fill_growth = 1.0;
  e.request_remesh();
  e.step(moved.centre, moved.radius, moved.walls, 1.0);
  ASSERT_FALSE(e.cholmod().ordering_given());
  EXPECT_FALSE(e.cholmod().metis_used());
  EXPECT_EQ(e.cholmod().fill(), solved(moved, Ordering::kGeometric).cholmod().fill());
}

TEST(GeometricOrdering, AskedForAfterAnotherOrderingIsComputedNotCarried) {
  const auto p = test::random_packing(800, 36, 0.02, 0.03);
  FlowEngine e = solved(p, Ordering::kAmd);
  ASSERT_EQ(e.cholmod().origin(), OrderingOrigin::kMinimumDegree);
  e.settings.ordering = Ordering::kGeometric;
  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_FALSE(e.cholmod().ordering_given());
  EXPECT_EQ(e.cholmod().origin(), OrderingOrigin::kGeometric);
  EXPECT_EQ(e.cholmod().fill(), solved(p, Ordering::kGeometric).cholmod().fill());
}
