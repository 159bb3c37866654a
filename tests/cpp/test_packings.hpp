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

// An engine set up as a permeameter along 'axis': pressure p_in on the min wall, 0 on the max.
inline FlowEngine permeameter(int axis = 0, double p_in = 1.0) {
  FlowEngine e;
  e.bc.is_pressure[2 * axis] = e.bc.is_pressure[2 * axis + 1] = true;
  e.bc.value[2 * axis] = p_in;
  return e;
}

}  // namespace pfv::test
