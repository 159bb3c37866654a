// Carrying the elimination order over a remesh: same pressures as a fresh ordering, fill
// within the bound, and a fresh ordering when the mesh changed too much.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "pfv/engine/flow_engine.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

// The packing with every centre moved at random by up to 'amplitude' (a fraction of rmin).
std::vector<Vec3> jiggled(const test::TestPacking& p, double amplitude, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> x = p.centre;
  const double rmin = *std::min_element(p.radius.begin(), p.radius.end());
  for (Vec3& c : x) c += amplitude * rmin * Vec3(u(gen), u(gen), u(gen));
  return x;
}

double max_abs_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

}  // namespace

TEST(OrderingReuse, SameMeshGetsTheSameOrderingAndPressures) {
  const auto p = test::random_packing(800, 81, 0.02, 0.03);
  FlowEngine e = test::permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1.0);
  ASSERT_FALSE(e.cholmod().ordering_given());  // the first mesh is ordered from scratch
  const double fill = e.cholmod().fill();
  const std::vector<double> before = e.pressure();
  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_TRUE(e.cholmod().ordering_given());
  EXPECT_EQ(e.cholmod().fill(), fill);
  EXPECT_LE(max_abs_difference(e.pressure(), before), 1e-12);
}

TEST(OrderingReuse, SmallMotionKeepsTheFillBoundAndTheSolution) {
  const auto p = test::random_packing(800, 82, 0.02, 0.03);
  FlowEngine reuse = test::permeameter(1), fresh = test::permeameter(1);
  fresh.settings.reuse_ordering = false;
  reuse.step(p.centre, p.radius, p.walls, 1.0);
  fresh.step(p.centre, p.radius, p.walls, 1.0);
  int reused = 0;
  for (int remesh = 1; remesh <= 4; ++remesh) {
    const auto x = jiggled(p, 0.01 * remesh, 90 + remesh);  // some flips, mostly the same cells
    reuse.request_remesh();
    fresh.request_remesh();
    reuse.step(x, p.radius, p.walls, 1.0);
    fresh.step(x, p.radius, p.walls, 1.0);
    reused += reuse.cholmod().ordering_given();
    EXPECT_FALSE(fresh.cholmod().ordering_given());
    // Never more fill than the bound allows over a fresh ordering of the same mesh (which
    // itself varies by a few % from mesh to mesh).
    EXPECT_LE(reuse.cholmod().fill(), reuse.settings.max_fill_growth * 1.05 * fresh.cholmod().fill());
    ASSERT_EQ(reuse.pressure().size(), fresh.pressure().size());
    EXPECT_LE(max_abs_difference(reuse.pressure(), fresh.pressure()), 1e-11);  // p_in = 1: round-off of two orderings
  }
  EXPECT_GT(reused, 0);
}

TEST(OrderingReuse, ChangedMeshFallsBackToAFreshOrdering) {
  const auto p = test::random_packing(800, 83, 0.02, 0.03);
  FlowEngine e = test::permeameter(1);
  e.settings.max_fill_growth = 1.0;  // any fill above the fresh ordering's is refused
  e.step(p.centre, p.radius, p.walls, 1.0);
  e.request_remesh();
  e.step(jiggled(p, 0.3, 7), p.radius, p.walls, 1.0);  // many flips: the old order fills more
  EXPECT_FALSE(e.cholmod().ordering_given());

  // Other spheres: nothing to match.
  const auto q = test::random_packing(700, 84, 0.02, 0.03);
  e.settings.max_fill_growth = 10;
  e.step(q.centre, q.radius, q.walls, 1.0);
  EXPECT_FALSE(e.cholmod().ordering_given());
}
