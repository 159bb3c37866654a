#include "pfv/model/periodic_forces.hpp"

#include <stdexcept>

namespace pfv {

std::vector<double> full_pressure(const CellGeometry& cells, const std::vector<double>& periodic_pressure,
                                  const Vec3& gradient) {
  std::vector<double> p(periodic_pressure.size());
  for (std::size_t c = 0; c < p.size(); ++c) p[c] = periodic_pressure[c] + gradient.dot(cells.power_centre[c]);
  return p;
}

void PeriodicForces::build(const ForceCache& cache, const PeriodicMesh& mesh) {
  closure_.assign(mesh.n_images(), Vec3::Zero());
  for (int v = 0; v < mesh.n_images(); ++v)
    for (const Vec3& u : cache.units(v)) closure_[v] += u;
}

std::vector<Vec3> PeriodicForces::apply(const ForceCache& cache, const PeriodicMesh& mesh,
                                        const std::vector<double>& cell_pressure, const Vec3& gradient,
                                        const Eigen::Matrix3d& h) const {
  if (static_cast<int>(closure_.size()) != mesh.n_images())
    throw std::logic_error("PeriodicForces::apply: not built for this mesh");
  std::vector<Vec3> per_image;
  cache.apply(cell_pressure, per_image);
  std::vector<Vec3> force(mesh.n_spheres, Vec3::Zero());
  const Vec3 g = h.transpose() * gradient;  // gradP . h o = (h^T gradP) . o
  for (int v = 0; v < mesh.n_images(); ++v) {
    const Offset& o = mesh.image_offset[v];
    const double shift = g.dot(Vec3(o[0], o[1], o[2]));
    force[mesh.image_sphere[v]] += per_image[v] - shift * closure_[v];
  }
  return force;
}

}  // namespace pfv
