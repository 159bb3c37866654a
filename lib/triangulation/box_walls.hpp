// The six axis-aligned walls that bound the packing, seen as planes.
//
// Wall w (0..5) is, in YADE's order, xmin, xmax, ymin, ymax, zmin, zmax: axis w/2, and
// the max side when w is odd. In the triangulation each wall is a fictitious sphere of
// near-infinite radius; the pore geometry uses the limit of that sphere, i.e. the plane.
#pragma once
#include <array>

#include "triangulation/vec3.hpp"

namespace pfv {

constexpr int kWallCount = 6;

inline int wall_axis(int w) { return w / 2; }
inline bool wall_is_max(int w) { return (w & 1) != 0; }

struct BoxWalls {
  std::array<double, kWallCount> coord{};  // position of each wall plane on its axis

  // Unit normal pointing into the domain.
  Vec3 inward_normal(int w) const {
    Vec3 n = Vec3::Zero();
    n[wall_axis(w)] = wall_is_max(w) ? -1.0 : 1.0;
    return n;
  }
  // Signed distance from the wall, positive inside the box.
  double height(int w, const Vec3& x) const {
    const double d = x[wall_axis(w)] - coord[w];
    return wall_is_max(w) ? -d : d;
  }
  Vec3 project(int w, const Vec3& x) const {
    Vec3 p = x;
    p[wall_axis(w)] = coord[w];
    return p;
  }
  double extent(int axis) const { return coord[2 * axis + 1] - coord[2 * axis]; }
};

}  // namespace pfv
