// Solid angle of the cone spanned by three unit directions from its apex
// (Van Oosterom & Strackee, 1983). atan2 keeps obtuse cones (negative denominator) right.
#pragma once
#include <cmath>

#include "triangulation/vec3.hpp"

namespace pfv {

inline double solid_angle(const Vec3& e1, const Vec3& e2, const Vec3& e3) {
  const double num = std::abs(e1.dot(e2.cross(e3)));
  const double den = 1.0 + e1.dot(e2) + e1.dot(e3) + e2.dot(e3);
  return 2.0 * std::atan2(num, den);
}

// Planar angle between two unit directions.
inline double planar_angle(const Vec3& e1, const Vec3& e2) { return std::atan2(e1.cross(e2).norm(), e1.dot(e2)); }

}  // namespace pfv
