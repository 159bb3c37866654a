// A periodic cell: the parallelepiped spanned by the columns of h (YADE's O.cell.hSize), with
// its origin at 0. It may be sheared (h not diagonal); a point x stands for every image
// x + h o, o in Z^3.
#pragma once
#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>

#include "triangulation/mesh.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

struct PeriodicCell {
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();

  double volume() const { return std::abs(h.determinant()); }
  Vec3 fractional(const Vec3& x) const { return h.partialPivLu().solve(x); }
  Vec3 translation(const Offset& o) const { return h * Vec3(o[0], o[1], o[2]); }
  // The distance between the two faces of the cell crossed by cell vector k: its thickness
  // along that period, what bounds how close two images of one point can be along it.
  double width(int k) const { return volume() / h.col((k + 1) % 3).cross(h.col((k + 2) % 3)).norm(); }
  double min_width() const { return std::min({width(0), width(1), width(2)}); }
};

}  // namespace pfv
