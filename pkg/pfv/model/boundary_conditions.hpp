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

}  // namespace pfv
