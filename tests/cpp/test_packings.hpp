// Deterministic packings shared by the unit tests.
#pragma once
#include <random>
#include <vector>

#include "pfv/engine/flow_engine.hpp"
#include "triangulation/box_walls.hpp"
#include "triangulation/vec3.hpp"

namespace pfv::test {

struct TestPacking {
  std::vector<Vec3> centre;
  std::vector<double> radius;
  BoxWalls walls;
};

// Non-overlapping spheres placed at random in the unit cube (rejection sampling).
inline TestPacking random_packing(int n, unsigned seed, double rmin = 0.03, double rmax = 0.05) {
  TestPacking p;
  p.walls.coord = {0, 1, 0, 1, 0, 1};
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  while (static_cast<int>(p.centre.size()) < n) {
    const double r = rmin + (rmax - rmin) * u(gen);
    const Vec3 x(r + (1 - 2 * r) * u(gen), r + (1 - 2 * r) * u(gen), r + (1 - 2 * r) * u(gen));
    bool free = true;
    for (std::size_t k = 0; k < p.centre.size() && free; ++k) free = (x - p.centre[k]).norm() > r + p.radius[k];
    if (free) {
      p.centre.push_back(x);
      p.radius.push_back(r);
    }
  }
  return p;
}

// side^3 spheres on a cubic lattice of spacing 1, centres jittered by up to 0.03 and radii 0.42
// +- 10 % (the benchmarks' packing), in walls 0.2 beyond the lattice's cells. Its
// near-cospherical cells flip under small motion.
inline TestPacking benchmark_lattice(int side, unsigned seed) {
  TestPacking p;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      for (int k = 0; k < side; ++k) {
        p.centre.emplace_back(i + 0.5 + 0.03 * u(gen), j + 0.5 + 0.03 * u(gen), k + 0.5 + 0.03 * u(gen));
        p.radius.push_back(0.42 * (1 + 0.1 * u(gen)));
      }
  p.walls.coord = {-0.2, side + 0.2, -0.2, side + 0.2, -0.2, side + 0.2};
  return p;
}

// An engine set up as a permeameter along 'axis': pressure p_in on the min wall, 0 on the max.
inline FlowEngine permeameter(int axis = 0, double p_in = 1.0) {
  FlowEngine e;
  e.bc.is_pressure[2 * axis] = e.bc.is_pressure[2 * axis + 1] = true;
  e.bc.value[2 * axis] = p_in;
  return e;
}

}  // namespace pfv::test
