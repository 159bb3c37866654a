// The force a throat's pressure difference puts on each of its three vertices, per unit
// difference (thesis 3.10, 3.13 with the corrected sign, 3.14): the sector of the facet inside
// the vertex's sphere takes the pressure term, and the facet's fluid area is the viscous term,
// shared by wetted area (equal shares among the spheres when no wetted area is known). Both the
// force cache of the step and the pressure/viscous split for validation are made of these.
#pragma once
#include <array>
#include <optional>

#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct FacetForceTerms {
  Vec3 normal;                     // unit, out of the facet's cell 0
  std::array<double, 3> pressure;  // per facet vertex: its sector area
  std::array<double, 3> viscous;   // per facet vertex: its share of the fluid area
};

// Empty for a facet of no area (it carries no force).
inline std::optional<FacetForceTerms> facet_force_terms(const Mesh& mesh, const FacetGeometry& facets, int f) {
  const Vec3& S = facets.area_vector[f];
  const double area = S.norm();
  if (area <= 0) return std::nullopt;
  const auto& wet = facets.wetted_area[f];
  const double wet_sum = wet[0] + wet[1] + wet[2];
  int spheres = 0;
  for (int v : facets.vertex[f]) spheres += mesh.is_wall(v) ? 0 : 1;
  FacetForceTerms t{S / area, facets.sector_area[f], {}};
  for (int s = 0; s < 3; ++s) {
    const double share = wet_sum > 0 ? wet[s] / wet_sum : (mesh.is_wall(facets.vertex[f][s]) ? 0.0 : 1.0 / spheres);
    t.viscous[s] = facets.fluid_area[f] * share;
  }
  return t;
}

}  // namespace pfv
