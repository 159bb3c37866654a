// A step is all or nothing: wherever it throws (its remesh, the mesh hook, the linear system, the
// pressure field, the results), the engine is left bit for bit as the last successful step left
// it, and a caller can undo a successful step (retract_step) until it accepts it. The mesh hook
// runs once on every new mesh, foreground or background, before the mesh's system.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <vector>

#include "pfv/engine/flow_engine.hpp"
#include "test_packings.hpp"

using namespace pfv;
using test::permeameter;
using test::TestPacking;

namespace {

constexpr double kDt = 1e-3;

// Everything a step may change that a caller can see.
struct Seen {
  std::vector<double> pressure, volume_rate;
  std::vector<Vec3> force, positions;
  int remesh_count, system_builds, inversion_remeshes, steps_since_remesh, cells;
  bool has_mesh;
  bool operator==(const Seen&) const = default;
};

Seen seen(const FlowEngine& e) {
  return {e.pressure(),
          e.volume_rates(),
          e.forces(),
          e.positions(),
          e.remesh_count(),
          e.system_builds(),
          e.inversion_remeshes(),
          e.remesher().steps_since_remesh(),
          e.has_mesh() ? e.mesh().n_cells() : 0,
          e.has_mesh()};
}

// The spheres moved a little (every step's dV/dt is then non-zero).
std::vector<Vec3> moved(const TestPacking& p, double by) {
  std::vector<Vec3> x = p.centre;
  for (std::size_t k = 0; k < x.size(); ++k) x[k][k % 3] += by * ((k % 2) ? 1 : -1);
  return x;
}

// How a step is made to throw: set up on the engine before the step, undone after it.
struct Failure {
  const char* name;
  std::function<void(FlowEngine&)> arm, disarm;
  bool needs_remesh = false;  // only a step that builds a mesh fails
};

std::vector<Failure> failures() {
  return {
      {"pressure field throws",
       [](FlowEngine& e) {
         e.pressure_field.wall = 1;
         e.pressure_field.evaluate = [](const std::vector<Vec3>&, std::vector<double>&) {
           throw std::runtime_error("field");
         };
       },
       [](FlowEngine& e) { e.pressure_field = PressureField{}; }},
      {"mesh hook throws", [](FlowEngine& e) { e.mesh_hook = [] { throw std::runtime_error("hook"); }; },
       [](FlowEngine& e) { e.mesh_hook = nullptr; }, true},
      {"singular system", [](FlowEngine& e) { e.bc.is_pressure = {}; },
       [](FlowEngine& e) { e.bc.is_pressure[0] = e.bc.is_pressure[1] = true; }},
      {"non-finite forces",
       [](FlowEngine& e) {
         e.settings.fluid_density = 1e308;
         e.settings.gravity = Vec3(0, 0, -1e10);
       },
       [](FlowEngine& e) {
         e.settings.fluid_density = 0;
         e.settings.gravity = Vec3::Zero();
       }},
  };
}

// The kinds of step: on the current mesh, with a requested remesh, with a scheduled remesh
// (in the foreground or adopted from the background).
enum class Kind { kSameMesh, kRequested, kScheduled, kBackground };

FlowEngine prepared(const TestPacking& p, Kind kind) {
  FlowEngine e = permeameter(0);
  // Remeshes at the first step, and when 2 steps have run on a mesh: at the third (scheduled), or
  // started at the third and adopted at the fourth (background).
  e.settings.mesh_update_interval = kind == Kind::kScheduled || kind == Kind::kBackground ? 2 : 1000;
  e.settings.background_remesh = kind == Kind::kBackground;
  e.step(p.centre, p.radius, p.walls, kDt);
  e.accept_step();
  e.step(moved(p, 1e-4), p.radius, p.walls, kDt);
  e.accept_step();
  if (kind == Kind::kRequested) e.request_remesh();
  if (kind == Kind::kBackground) {  // the third step starts a remesh, the next one adopts it
    e.step(moved(p, 2e-4), p.radius, p.walls, kDt);
    e.accept_step();
    e.remesher().wait();
  }
  return e;
}

TEST(StepUndo, AStepThatThrowsLeavesTheEngineAsItWas) {
  const TestPacking p = test::random_packing(120, 3);
  int cases = 0;
  for (Kind kind : {Kind::kSameMesh, Kind::kRequested, Kind::kScheduled, Kind::kBackground})
    for (const Failure& f : failures()) {
      if (f.needs_remesh && kind == Kind::kSameMesh) continue;
      FlowEngine e = prepared(p, kind);
      const int remeshes = e.remesh_count();
      const Seen before = seen(e);
      f.arm(e);
      const auto next = moved(p, 5e-4);
      EXPECT_ANY_THROW(e.step(next, p.radius, p.walls, kDt)) << f.name;
      f.disarm(e);
      EXPECT_TRUE(seen(e) == before) << f.name << ", kind " << static_cast<int>(kind);
      // Then it runs on, and gives what an engine that never failed gives; a background mesh the
      // failed step had adopted is gone with it, and the next step remeshes in the foreground.
      e.step(next, p.radius, p.walls, kDt);
      FlowEngine reference = prepared(p, kind);
      if (kind == Kind::kBackground) reference.request_remesh();
      reference.step(next, p.radius, p.walls, kDt);
      EXPECT_EQ(e.pressure(), reference.pressure()) << f.name << ", kind " << static_cast<int>(kind);
      EXPECT_EQ(e.forces(), reference.forces()) << f.name << ", kind " << static_cast<int>(kind);
      EXPECT_EQ(e.remesh_count(), reference.remesh_count()) << f.name;
      if (kind != Kind::kSameMesh) {
        EXPECT_EQ(e.remesh_count(), remeshes + 1) << f.name << ": the step remeshed";
      }
      ++cases;
    }
  EXPECT_EQ(cases, 15);
}

TEST(StepUndo, RetractUndoesASuccessfulStepUntilAccepted) {
  const TestPacking p = test::random_packing(120, 4);
  for (bool remesh : {false, true}) {
    FlowEngine e = prepared(p, Kind::kSameMesh);
    e.settings.fluid_bulk_modulus = 1e4;  // the pressures carry state from step to step
    e.step(moved(p, 2e-4), p.radius, p.walls, kDt);
    e.accept_step();
    const Seen before = seen(e);
    if (remesh) e.request_remesh();
    e.step(moved(p, 4e-4), p.radius, p.walls, kDt);
    EXPECT_FALSE(seen(e) == before);
    EXPECT_TRUE(e.retract_step());
    EXPECT_TRUE(seen(e) == before) << "remesh " << remesh;
    EXPECT_FALSE(e.retract_step());  // once
    // The retracted step again: the same result as an engine that made it once.
    FlowEngine reference = prepared(p, Kind::kSameMesh);
    reference.settings.fluid_bulk_modulus = 1e4;
    reference.step(moved(p, 2e-4), p.radius, p.walls, kDt);
    if (remesh) {
      reference.request_remesh();
      e.request_remesh();
    }
    reference.step(moved(p, 4e-4), p.radius, p.walls, kDt);
    e.step(moved(p, 4e-4), p.radius, p.walls, kDt);
    EXPECT_EQ(e.pressure(), reference.pressure()) << "remesh " << remesh;
    e.accept_step();
    EXPECT_FALSE(e.retract_step());
  }
}

TEST(StepUndo, TheMeshHookRunsOnceOnEveryNewMeshBeforeItsSystem) {
  const TestPacking p = test::random_packing(120, 5);
  for (bool background : {false, true}) {
    FlowEngine e = permeameter(0);
    e.settings.mesh_update_interval = 2;
    e.settings.background_remesh = background;
    int calls = 0;
    // Blocks every cell touching the x-min wall's half of the box at zero pressure: a change the
    // system must see on the mesh's first step.
    e.mesh_hook = [&] {
      ++calls;
      const CellGeometry& g = e.cells();
      for (int c = 0; c < e.mesh().n_cells(); ++c)
        if (g.power_centre[c][0] < 0.25) e.block_cell(c, true);
    };
    std::vector<double> first_pressures;
    for (int k = 0; k < 9; ++k) {
      e.step(p.centre, p.radius, p.walls, kDt);
      e.accept_step();
      if (background) e.remesher().wait();
      EXPECT_EQ(calls, e.remesh_count()) << "background " << background;
      EXPECT_FALSE(e.cell_conditions().blocked.empty());
      if (k == 0) first_pressures = e.pressure();
      if (e.pressure().size() == first_pressures.size()) {
        double worst = 0;
        for (std::size_t c = 0; c < first_pressures.size(); ++c)
          worst = std::max(worst, std::abs(e.pressure()[c] - first_pressures[c]));
        EXPECT_LT(worst, 1e-12) << "step " << k << ", background " << background;
      }
    }
    EXPECT_GE(e.remesh_count(), 4);
  }
}

TEST(StepUndo, TheMeshHookCannotStepOrRemesh) {
  const TestPacking p = test::random_packing(60, 6);
  FlowEngine e = permeameter(0);
  e.mesh_hook = [&] { e.step(p.centre, p.radius, p.walls, kDt); };
  EXPECT_THROW(e.step(p.centre, p.radius, p.walls, kDt), std::logic_error);
  EXPECT_FALSE(e.has_mesh());  // the first step undone: no mesh
  e.mesh_hook = [&] { e.release(); };
  EXPECT_THROW(e.step(p.centre, p.radius, p.walls, kDt), std::logic_error);
  e.mesh_hook = nullptr;
  e.step(p.centre, p.radius, p.walls, kDt);
  EXPECT_TRUE(e.has_mesh());
}

}  // namespace
