// The fluid force on every sphere and wall split into its pressure and viscous parts, for
// comparisons with a Stokes solution (doc/validation.md section 7). The sum of the two parts is
// the force of the force cache (force_cache.hpp): the pressure part is the sector term (thesis
// 3.10) and, for walls, the pressure on the wall footprint; the viscous part is the facet's fluid
// area share (3.13, 3.14). Computed on demand from the mesh; the step does not use it.
#pragma once
#include <vector>

#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct ForceParts {
  std::vector<Vec3> pressure;  // per mesh vertex: spheres, then the six walls
  std::vector<Vec3> viscous;
};

ForceParts split_fluid_forces(const Mesh& mesh, const FacetGeometry& facets, const Packing& packing,
                              const std::vector<double>& cell_pressure);

}  // namespace pfv
