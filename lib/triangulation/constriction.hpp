// The constriction of a throat: the largest circle in the plane of a facet that touches, without
// overlapping, the cross-sections of the facet's spheres (the plane holds their centres, so the
// cross-sections are great circles) and, for a facet with wall vertices, the traces of the walls
// in that plane. Its radius is the throat's inscribed radius (YADE's getConstrictions).
#pragma once
#include <array>

#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct Constriction {
  double radius = 0;  // 0 if the circles leave no gap (overlapping spheres) or the facet is flat
  Vec3 centre = Vec3::Zero();
};

// facet: three mesh vertices, at least one of them a sphere.
Constriction throat_constriction(const Mesh& mesh, const std::array<int, 3>& facet, const Packing& packing);

}  // namespace pfv
