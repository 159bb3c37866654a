// Flow boundary conditions, with YADE's FlowEngine meanings.
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "triangulation/box_walls.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

struct PointCondition {
  Vec3 position;
  double value;  // a pressure, or an injected flux (volume per time, positive into the pore)
};

// A pressure that varies along one axis over one pressure wall (YADE's boundaryXPos and
// boundaryPressure, on ymax along x): each Dirichlet cell of the wall takes the pressure
// interpolated linearly at its power centre; cells beyond the first or last point keep the
// wall's value. Empty: the wall's value everywhere.
struct PressureProfile {
  int wall = 3;
  int axis = 0;
  std::vector<double> position, pressure;  // positions increasing
  bool empty() const { return position.empty(); }
  bool operator==(const PressureProfile&) const = default;
};

// Pressures of one pressure wall's Dirichlet cells that change from step to step (YADE's
// waveAction, pfv.waves). Called once per step, after any remesh, with the power centres of the
// wall's Dirichlet cells; it fills one pressure per cell, which replaces the wall's value (and
// any PressureProfile there). Only Dirichlet values change, i.e. the right-hand side: a time-
// dependent load must never cost a new system or factor. Held by the engine, not in
// BoundaryConditions, so that it is never copied into a background remesh (it may hold a Python
// callable, which only the thread that holds the GIL may copy or drop).
struct PressureField {
  int wall = -1;  // -1: none
  // (positions, pressures): pressures has one entry per position on return; may throw.
  std::function<void(const std::vector<Vec3>&, std::vector<double>&)> evaluate;
  bool active() const { return wall >= 0 && static_cast<bool>(evaluate); }
};

struct BoundaryConditions {
  std::array<bool, kWallCount> is_pressure{};  // else no-flux
  std::array<double, kWallCount> value{};
  std::vector<PointCondition> imposed_pressure;
  std::vector<PointCondition> imposed_flux;
  PressureProfile profile;
};

// The profile's pressure at x, or 'outside' beyond its points (or without a profile).
double profile_pressure(const PressureProfile& profile, double x, double outside);

// Throws std::invalid_argument naming the first non-finite boundary value, imposed point or
// imposed value, or a profile that is not two or more finite points at increasing positions. Whether an imposed point
// lies in the pore space is known only on a mesh (build_linear_system checks it there).
void validate(const BoundaryConditions& bc);

}  // namespace pfv
