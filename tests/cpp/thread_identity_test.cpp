// A step at two OpenMP threads gives the pressures, forces and volume rates of a step at one, to
// the bit, on a packing large enough that every loop of the step may run on a team (its cells,
// force terms and unknowns above kMinParallelLoop; whether it does is measured, LoopChoice); the
// sums over cells (the meshed and inverted volumes) too, being added by fixed chunks, and the
// strain (a maximum). A loop whose iterations race (a shared accumulator, two threads writing one
// force) changes them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pfv/common/parallel.hpp"
#include "pfv/engine/flow_engine.hpp"
#include "test_packings.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace pfv;
using test::permeameter;
using test::TestPacking;

namespace {

// Every sphere's own constant velocity: 'speed' along a random direction.
std::vector<Vec3> velocities(std::size_t n, double speed, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> v(n);
  for (Vec3& x : v) {
    x = Vec3(g(gen), g(gen), g(gen));
    x *= speed / x.norm();
  }
  return v;
}

// Restores the caller's thread count when it goes out of scope.
class Threads {
 public:
  explicit Threads(int n) {
#ifdef _OPENMP
    omp_set_num_threads(n);
#endif
  }
  ~Threads() {
#ifdef _OPENMP
    omp_set_num_threads(before_);
#endif
  }
  Threads(const Threads&) = delete;
  Threads& operator=(const Threads&) = delete;

 private:
  int before_ = max_threads();
};

FlowEngine drifting_engine(SolverKind solver) {
  FlowEngine e = permeameter(1, 100.0);
  e.settings.solver = solver;
  e.settings.mesh_update_interval = 1 << 30;  // the same mesh for every step: only the motion changes
  e.settings.def_tolerance = 0;
  return e;
}

void expect_same_steps(SolverKind solver) {
#ifndef _OPENMP
  GTEST_SKIP() << "built without OpenMP";
#endif
  const TestPacking p = test::benchmark_lattice(16, 5);
  const std::vector<Vec3> v = velocities(p.centre.size(), 0.02, 6);
  FlowEngine one = drifting_engine(solver), two = drifting_engine(solver);
  std::vector<Vec3> x = p.centre;
  const double dt = 1e-3;
  for (int s = 0; s < 4; ++s) {
    {
      const Threads t(1);
      one.step(x, p.radius, p.walls, dt);
    }
    {
      const Threads t(2);
      ASSERT_EQ(max_threads(), 2);
      two.step(x, p.radius, p.walls, dt);
    }
    // Every loop of the step has enough items for a team.
    ASSERT_GT(two.mesh().n_cells(), kMinParallelLoop);
    ASSERT_GT(two.system().n_unknowns(), kMinParallelLoop);
    EXPECT_EQ(one.pressure(), two.pressure()) << "step " << s;
    EXPECT_EQ(one.volume_rates(), two.volume_rates()) << "step " << s;
    ASSERT_EQ(one.forces().size(), two.forces().size());
    for (std::size_t k = 0; k < one.forces().size(); ++k)
      ASSERT_EQ(one.forces()[k], two.forces()[k]) << "vertex " << k << ", step " << s;
    EXPECT_EQ(one.inverted_cells(), two.inverted_cells()) << "step " << s;
    EXPECT_EQ(one.inverted_volume_fraction(), two.inverted_volume_fraction()) << "step " << s;
    EXPECT_EQ(one.remesher().strain(), two.remesher().strain()) << "step " << s;
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += v[k];
  }
  // The motion turned cells inside out (the reductions of the inverted volume summed something),
  // without a remesh out of schedule.
  EXPECT_GT(two.inverted_cells(), 0);
  EXPECT_EQ(two.remesh_count(), 1);
}

}  // namespace

TEST(ThreadIdentity, CholeskyStepIsTheSameOnTwoThreads) { expect_same_steps(SolverKind::kCholesky); }

#ifdef PFV_WITH_HYPRE
TEST(ThreadIdentity, MultigridStepIsTheSameOnTwoThreads) { expect_same_steps(SolverKind::kMultigrid); }
#endif
