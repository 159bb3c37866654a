// Periodic packings shared by the unit tests of periodic meshes.
#pragma once
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "triangulation/periodic_cell.hpp"
#include "triangulation/vec3.hpp"

namespace pfv::test {

struct PeriodicPacking {
  std::vector<Vec3> centre;
  std::vector<double> radius;
  PeriodicCell cell;
};

inline Eigen::Matrix3d diagonal(double a, double b, double c) { return Vec3(a, b, c).asDiagonal(); }

// The shortest vector between the images of x and y (|fractional difference| <= 1/2 on each
// axis, then the 27 neighbouring images: exact enough for a sheared cell too).
inline Vec3 periodic_difference(const PeriodicCell& cell, const Vec3& x, const Vec3& y) {
  Vec3 f = cell.fractional(x - y);
  for (int a = 0; a < 3; ++a) f[a] -= std::round(f[a]);
  Vec3 best = cell.h * f;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        const Vec3 d = cell.h * (f + Vec3(i, j, k));
        if (d.norm() < best.norm()) best = d;
      }
  return best;
}

// Non-overlapping spheres (periodic distances) at random in the cell.
inline PeriodicPacking random_periodic(int n, unsigned seed, const Eigen::Matrix3d& h, double rmin, double rmax) {
  PeriodicPacking p;
  p.cell.h = h;
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (long attempt = 0; static_cast<int>(p.centre.size()) < n; ++attempt) {
    if (attempt > 1000000) throw std::runtime_error("random_periodic: no room for the spheres asked for");
    const double r = rmin + (rmax - rmin) * u(gen);
    const Vec3 x = h * Vec3(u(gen), u(gen), u(gen));
    bool free = true;
    for (std::size_t k = 0; k < p.centre.size() && free; ++k)
      free = periodic_difference(p.cell, x, p.centre[k]).norm() > r + p.radius[k];
    if (free) {
      p.centre.push_back(x);
      p.radius.push_back(r);
    }
  }
  return p;
}

// The same infinite packing in a cell twice as large along each vector: 2 x 2 x 2 copies.
inline PeriodicPacking tiled(const PeriodicPacking& p) {
  PeriodicPacking big;
  big.cell.h = 2 * p.cell.h;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
        for (std::size_t s = 0; s < p.centre.size(); ++s) {
          big.centre.push_back(p.centre[s] + p.cell.translation({i, j, k}));
          big.radius.push_back(p.radius[s]);
        }
  return big;
}

}  // namespace pfv::test
