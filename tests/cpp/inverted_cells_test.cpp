// Cells turned inside out between two remeshes: the step runs on with signed volumes and keeps
// the mass balance exact, its error against a fresh mesh follows the motion since the remesh
// (not the inversions), and motion past any useful remesh schedule remeshes at once.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "test_packings.hpp"

using namespace pfv;
using test::permeameter;
using test::TestPacking;

namespace {

constexpr double kStatic = 1e10;  // a time step that makes dV/dt negligible: flow from the walls alone

// One random unit direction per sphere.
std::vector<Vec3> directions(std::size_t n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> d(n);
  for (Vec3& x : d) {
    x = Vec3(g(gen), g(gen), g(gen));
    x /= x.norm();
  }
  return d;
}

// Every sphere moved by 'distance' along its own direction (the lattice's margin to the walls
// keeps the centres inside for the distances used here).
std::vector<Vec3> drifted(const std::vector<Vec3>& centre, const std::vector<Vec3>& dir, double distance) {
  std::vector<Vec3> x(centre.size());
  for (std::size_t k = 0; k < x.size(); ++k) x[k] = centre[k] + distance * dir[k];
  return x;
}

// 'rounds' times, every sphere in turn jumps by 'distance' in a random direction, unless that
// would bring it closer than 0.05 to another sphere's surface (then it tries another direction,
// or stays): a random walk of the packing that never overlaps spheres.
std::vector<Vec3> jumped(const TestPacking& p, double distance, int rounds, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> g;
  std::vector<Vec3> x = p.centre;
  for (int round = 0; round < rounds; ++round)
    for (std::size_t k = 0; k < x.size(); ++k)
      for (int attempt = 0; attempt < 20; ++attempt) {
        Vec3 d(g(gen), g(gen), g(gen));
        const Vec3 trial = x[k] + distance * d / d.norm();
        bool free = true;
        for (int a = 0; a < 3 && free; ++a)
          free = trial[a] - p.radius[k] > p.walls.coord[2 * a] && trial[a] + p.radius[k] < p.walls.coord[2 * a + 1];
        for (std::size_t j = 0; j < x.size() && free; ++j)
          free = j == k || (x[j] - trial).norm() > p.radius[j] + p.radius[k] + 0.05;
        if (free) {
          x[k] = trial;
          break;
        }
      }
  return x;
}

FlowEngine never_remeshing(FlowEngine e) {
  e.settings.mesh_update_interval = 1 << 30;
  e.settings.def_tolerance = 0;
  return e;
}

double relative_force_error(const FlowEngine& a, const FlowEngine& b, std::size_t n_spheres) {
  double diff = 0, norm = 0;
  for (std::size_t k = 0; k < n_spheres; ++k) {
    diff += (a.forces()[k] - b.forces()[k]).squaredNorm();
    norm += b.forces()[k].squaredNorm();
  }
  return std::sqrt(diff / norm);
}

}  // namespace

TEST(InvertedCells, TheStepRunsOnAndConservesMass) {
  // Every sphere drifts by 0.002 spacing per step and the max-y wall closes in: after 20 steps
  // cells are inside out. The step runs on with the old mesh, and its volume rates sum to the rate
  // of change of the box's volume, as the cells' signed volumes still tile the box. With
  // |volume| instead, an inverted cell's rate had the wrong sign: a spurious source.
  const TestPacking p = test::benchmark_lattice(10, 3);
  const std::vector<Vec3> dir = directions(p.centre.size(), 4);
  FlowEngine e = never_remeshing(permeameter(1));
  const double dt = 1e-3, wall_speed = 0.05;
  BoxWalls walls = p.walls;
  e.step(p.centre, p.radius, walls, dt);
  double box = walls.extent(0) * walls.extent(1) * walls.extent(2);
  for (int s = 1; s <= 20; ++s) {
    walls.coord[3] -= wall_speed * dt;
    e.step(drifted(p.centre, dir, 0.002 * s), p.radius, walls, dt);
    const double box_now = walls.extent(0) * walls.extent(1) * walls.extent(2);
    const double box_rate = (box_now - box) / dt;
    box = box_now;
    double magnitude = 0;  // the scale the balance is exact against
    for (double r : e.volume_rates()) magnitude += std::abs(r);
    EXPECT_NEAR(volume_rate_total(e), box_rate, 1e-10 * magnitude) << "step " << s;
    // Incompressible: what the pores gain flows in through the pressure walls (outflow positive).
    const double outflow = boundary_flux(e, 2) + boundary_flux(e, 3);
    EXPECT_NEAR(outflow, -volume_rate_total(e), 1e-8 * (std::abs(boundary_flux(e, 2)) + magnitude)) << "step " << s;
  }
  EXPECT_GT(e.inverted_cells(), 0);
  EXPECT_LT(e.inverted_volume_fraction(), 0.02);
  EXPECT_EQ(e.remesh_count(), 1);
  EXPECT_EQ(e.inversion_remeshes(), 0);
}

TEST(InvertedCells, TheErrorAgainstAFreshMeshFollowsTheMotion) {
  // The run-on mesh keeps the conductances and force areas of the positions it was built at; its
  // error against a mesh built at the current positions grows with the motion since the remesh,
  // about linearly in the forces (measured: 1.5-1.8 x the drift in spacings), and the inverted
  // cells add no jump to it. Bound: twice the drift, for the forces and the flux.
  const TestPacking p = test::benchmark_lattice(10, 5);
  const std::vector<Vec3> dir = directions(p.centre.size(), 6);
  for (double drift : {0.01, 0.02, 0.05}) {
    FlowEngine stale = never_remeshing(permeameter(1, 100.0));
    stale.step(p.centre, p.radius, p.walls, kStatic);
    const std::vector<Vec3> x = drifted(p.centre, dir, drift);
    stale.step(x, p.radius, p.walls, kStatic);
    FlowEngine fresh = permeameter(1, 100.0);
    fresh.step(x, p.radius, p.walls, kStatic);
    EXPECT_GT(stale.inverted_cells(), 0) << "drift " << drift;
    EXPECT_EQ(stale.remesh_count(), 1) << "drift " << drift;
    const double flux_error = std::abs(boundary_flux(stale, 2) / boundary_flux(fresh, 2) - 1);
    const double force_error = relative_force_error(stale, fresh, p.centre.size());
    EXPECT_LE(flux_error, 2 * drift) << "drift " << drift;
    EXPECT_LE(force_error, 2 * drift) << "drift " << drift;
    EXPECT_GT(force_error, 0.2 * drift) << "drift " << drift << ": the meshes should differ";
  }
}

TEST(InvertedCells, MotionPastAnyScheduleRemeshesAtOnce) {
  // The spheres random-walk about half a spacing since the remesh (four jumps of a quarter
  // spacing): more than 2 % of the volume is inside out, the old mesh describes the pore space in
  // name only. The step remeshes at these positions and gives what a fresh engine gives.
  const TestPacking p = test::benchmark_lattice(10, 7);
  FlowEngine e = never_remeshing(permeameter(1, 100.0));
  e.step(p.centre, p.radius, p.walls, kStatic);
  const std::vector<Vec3> x = jumped(p, 0.25, 4, 8);
  e.step(x, p.radius, p.walls, kStatic);
  EXPECT_EQ(e.inversion_remeshes(), 1);
  EXPECT_EQ(e.remesh_count(), 2);
  EXPECT_LT(e.inverted_volume_fraction(), 0.02);
  FlowEngine fresh = permeameter(1, 100.0);
  fresh.step(x, p.radius, p.walls, kStatic);
  EXPECT_NEAR(boundary_flux(e, 2), boundary_flux(fresh, 2), 1e-9 * std::abs(boundary_flux(fresh, 2)));
}
