// Small vector vocabulary shared by the triangulation and the flow model.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace pfv {
using Vec3 = Eigen::Vector3d;
}  // namespace pfv
