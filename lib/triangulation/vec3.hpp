// Small vector vocabulary shared by the triangulation and the flow model.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace pfv {
using Vec3 = Eigen::Vector3d;

// Loops shorter than this run on one thread: waking a thread team costs more than the loop,
// and far more when the cores are shared with other processes.
constexpr int kMinParallelLoop = 20000;
}  // namespace pfv
