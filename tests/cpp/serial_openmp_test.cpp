// CHOLMOD's 4-thread teams are capped to the calling thread, and the caller's OpenMP settings
// survive a factorisation.
#include <gtest/gtest.h>

#include <thread>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "pfv/engine/flow_engine.hpp"
#include "pfv/linalg/serial_openmp.hpp"
#include "test_packings.hpp"

using namespace pfv;

#ifdef _OPENMP
namespace {
int team_size(int requested) {
  int size = 0;
#pragma omp parallel num_threads(requested)
  {
#pragma omp single
    size = omp_get_num_threads();
  }
  return size;
}
}  // namespace

TEST(SerialOpenMp, CapsExplicitTeamsAndRestores) {
  omp_set_dynamic(0);
  omp_set_num_threads(3);
  ASSERT_EQ(team_size(4), 4);  // an explicit num_threads clause overrides omp_set_num_threads
  {
    const SerialOpenMpRegions serial;
    EXPECT_EQ(team_size(4), 1);
    // Another thread's regions are not capped (the DEM thread during a background remesh).
    int other = 0;
    std::thread t([&] { other = team_size(2); });
    t.join();
    EXPECT_EQ(other, 2);
  }
  EXPECT_EQ(team_size(4), 4);
  EXPECT_EQ(omp_get_max_threads(), 3);
  EXPECT_EQ(omp_get_dynamic(), 0);
  omp_set_num_threads(1);
}

TEST(SerialOpenMp, FactorisationKeepsTheCallersSettings) {
  const auto p = test::random_packing(300, 7, 0.02, 0.03);
  FlowEngine e = test::permeameter(1);
  omp_set_dynamic(0);
  omp_set_num_threads(2);
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_TRUE(e.cholmod().ready());
  EXPECT_EQ(omp_get_max_threads(), 2);
  EXPECT_EQ(omp_get_dynamic(), 0);
  omp_set_num_threads(1);
}
#endif
