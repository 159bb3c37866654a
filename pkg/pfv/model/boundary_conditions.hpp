// Flow boundary conditions, with YADE's FlowEngine meanings.
#pragma once
#include <array>
#include <vector>

#include "triangulation/box_walls.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

struct PointCondition {
  Vec3 position;
  double value;  // a pressure, or an injected flux (volume per time, positive into the pore)
};

struct BoundaryConditions {
  std::array<bool, kWallCount> is_pressure{};  // else no-flux
  std::array<double, kWallCount> value{};
  std::vector<PointCondition> imposed_pressure;
  std::vector<PointCondition> imposed_flux;
};

// Throws std::invalid_argument naming the first non-finite boundary value, imposed point or
// imposed value. Whether an imposed point lies in the pore space is known only on a mesh
// (build_linear_system checks it there).
void validate(const BoundaryConditions& bc);

}  // namespace pfv
