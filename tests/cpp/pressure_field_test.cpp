// FlowEngine::pressure_field, the time-dependent load of a pressure wall (doc/waves.md): its values
// are Dirichlet values only (no new system), it is called once per step with the wall's cells,
// bad values leave the engine unchanged, and the pressures are linear in the load.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "pfv/engine/flow_engine.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

// ymax loaded with a*(1 + cos(pi x)), every other wall impermeable.
FlowEngine loaded(double* amplitude, int* calls) {
  FlowEngine e;
  e.bc.is_pressure[3] = true;
  e.pressure_field.wall = 3;
  e.pressure_field.evaluate = [amplitude, calls](const std::vector<Vec3>& at, std::vector<double>& p) {
    ++*calls;
    p.resize(at.size());
    for (std::size_t i = 0; i < at.size(); ++i) p[i] = *amplitude * (1 + std::cos(M_PI * at[i].x()));
  };
  return e;
}

}  // namespace

TEST(PressureField, RightHandSideOnlyOncePerStepAndLinear) {
  const auto p = test::random_packing(250, 7);
  double a = 1.0;
  int calls = 0;
  FlowEngine e = loaded(&a, &calls);
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(calls, 1);
  const std::vector<double> first = e.pressure();
  int wall_cells = 0;
  for (std::size_t c = 0; c < first.size(); ++c)
    if (e.system().source[c].is_wall(3)) {
      ++wall_cells;
      EXPECT_DOUBLE_EQ(first[c], 1 + std::cos(M_PI * e.cells().power_centre[c].x()));
    }
  EXPECT_GT(wall_cells, 10);
  const int systems = e.system_builds();
  for (int k = 2; k <= 4; ++k) {
    a = k;
    e.step(p.centre, p.radius, p.walls, 1.0);
    EXPECT_EQ(calls, k);
    for (std::size_t c = 0; c < first.size(); ++c) EXPECT_NEAR(e.pressure()[c], k * first[c], 1e-12 * k);
  }
  EXPECT_EQ(e.system_builds(), systems);
  EXPECT_EQ(e.remesh_count(), 1);
  EXPECT_EQ(e.field_evaluations(), 4);
}

TEST(PressureField, BadValuesLeaveTheEngineUnchanged) {
  const auto p = test::random_packing(250, 7);
  double a = 1.0;
  int calls = 0;
  FlowEngine e = loaded(&a, &calls);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const std::vector<double> before = e.pressure();
  a = std::nan("");
  EXPECT_THROW(e.step(p.centre, p.radius, p.walls, 1.0), std::invalid_argument);
  e.pressure_field.evaluate = [](const std::vector<Vec3>& at, std::vector<double>& v) { v.assign(at.size() + 1, 0); };
  EXPECT_THROW(e.step(p.centre, p.radius, p.walls, 1.0), std::invalid_argument);
  EXPECT_EQ(e.pressure(), before);
  e.pressure_field = {};  // none: the wall's value again
  e.step(p.centre, p.radius, p.walls, 1.0);
  for (std::size_t c = 0; c < before.size(); ++c) EXPECT_EQ(e.pressure()[c], 0.0);
}
