// Where a pore cell's pressure comes from in the pressure system: solved for, or imposed by a
// pressure wall, an imposed point, or the cell's own condition; or the cell is blocked. One
// value per cell of a PressureSystem. A new kind of boundary condition is a new Kind here, set
// by the assembly and valued by apply_dirichlet_values (pressure_system.cpp).
#pragma once
#include <cstdint>

namespace pfv {

struct BoundarySource {
  enum class Kind : std::uint8_t {
    kUnknown,       // the pressure is solved for
    kWall,          // a Dirichlet cell of pressure wall 'index'
    kImposedPoint,  // the Dirichlet cell of imposed pressure point 'index'
    kCellImposed,   // imposed on the cell itself: its pressure is kept
    kBlocked,       // no unknown, no flux through its throats; its pressure is kept
  };
  Kind kind = Kind::kUnknown;
  int index = -1;  // the wall or the imposed point; -1 for the other kinds

  static constexpr BoundarySource unknown() { return {}; }
  static constexpr BoundarySource wall(int w) { return {Kind::kWall, w}; }
  static constexpr BoundarySource imposed_point(int i) { return {Kind::kImposedPoint, i}; }
  static constexpr BoundarySource cell_imposed() { return {Kind::kCellImposed, -1}; }
  static constexpr BoundarySource blocked() { return {Kind::kBlocked, -1}; }

  constexpr bool is_unknown() const { return kind == Kind::kUnknown; }
  constexpr bool is_wall() const { return kind == Kind::kWall; }
  constexpr bool is_wall(int w) const { return kind == Kind::kWall && index == w; }
  constexpr bool is_imposed_point() const { return kind == Kind::kImposedPoint; }
  constexpr bool is_blocked() const { return kind == Kind::kBlocked; }
  // A wall or an imposed point: the pressure is set from the boundary values at every step.
  constexpr bool takes_boundary_value() const { return kind == Kind::kWall || kind == Kind::kImposedPoint; }
  // Any pressure the system does not solve for but that anchors it (not a blocked cell).
  constexpr bool imposes_pressure() const { return takes_boundary_value() || kind == Kind::kCellImposed; }

  constexpr bool operator==(const BoundarySource&) const = default;
};

}  // namespace pfv
