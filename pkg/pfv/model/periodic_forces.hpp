// The fluid force on each sphere of a periodic packing, from the force cache (force_cache.hpp) of
// the periodic mesh, whose vertices are images: F_v = sum_c p_c S(v, c) over the stored cells c
// around image v, at their full pressures p_c = p~_c + gradP . P_c (P_c the power centre).
//
// Image v = sphere s translated by o_v periods touches its cells where they are stored; around
// the sphere itself the same cells lie translated by -o_v, where the pressure is lower by
// gradP . h o_v. So F_s = sum over s's images v of F_v - (gradP . h o_v) sum_c S(v, c). The sums
// sum_c S(v, c) (what a uniform unit pressure puts on the image) are kept per remesh.
#pragma once
#include <vector>

#include "pfv/model/force_cache.hpp"
#include "triangulation/periodic_mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

// Per stored cell, p~ + gradP . P.
std::vector<double> full_pressure(const CellGeometry& cells, const std::vector<double>& periodic_pressure,
                                  const Vec3& gradient);

class PeriodicForces {
 public:
  void build(const ForceCache& cache, const PeriodicMesh& mesh);
  // Per sphere, the force for the cells' full pressures; h the cell's current vectors.
  std::vector<Vec3> apply(const ForceCache& cache, const PeriodicMesh& mesh, const std::vector<double>& cell_pressure,
                          const Vec3& gradient, const Eigen::Matrix3d& h) const;

 private:
  std::vector<Vec3> closure_;  // per image, sum_c S(v, c)
};

}  // namespace pfv
