// Optional viscous shear force between neighbouring spheres (YADE's `viscousShear`; thesis
// 6.29-6.30, Marzougui's extension): F = mu * dV_t / R_h * S_vor on each pair, dV_t being the
// tangential part of the relative velocity.
//
// A pair is an edge of the regular triangulation. Its surface S_vor is the power-diagram
// facet dual to the edge: the polygon of the power centres of the cells around the edge,
// in ring order (walls clip it, since wall-cell power centres lie on the wall planes). Its
// R_h is the hydraulic radius of the union of the throats around the edge: total fluid
// volume over total wetted area, i.e. the wetted-area weighted mean of the throats' (3.5).
// Sphere-wall edges are pairs too, with no-slip walls only (a slip wall takes no shear);
// a wall does not move along its plane. Choices and omissions: doc/model.md.
//
// Everything but the velocities is fixed between remeshes and built with the pore mesh,
// and only when the term is on.
#pragma once
#include <array>
#include <vector>

#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct ViscousShear {
  // Edge e joins sphere a[e] to vertex b[e] (a sphere, or a wall n_spheres + w).
  std::vector<int> a, b;
  std::vector<Vec3> direction;           // unit, from a to b (for a wall: its outward normal)
  std::vector<double> area;              // S_vor
  std::vector<double> hydraulic_radius;  // R_h of the pair; 0 if no fluid around the edge
  int open_rings = 0;                    // edges skipped because a cell around them is not a pore cell

  int size() const { return static_cast<int>(a.size()); }

  // Adds the shear force on every vertex for sphere velocities (x - x_prev) / dt to 'force'
  // and writes it alone to 'shear' (resized to force.size()). Pairs without fluid (R_h = 0)
  // or with a zero facet (degenerate lattices) take no force.
  void add_forces(const std::vector<Vec3>& centres, const std::vector<Vec3>& centres_prev, double dt, double viscosity,
                  std::vector<Vec3>& force, std::vector<Vec3>& shear) const;
  // The same for given sphere velocities (the linearised operator of the stability limit).
  void add_velocity_forces(const std::vector<Vec3>& velocity, double viscosity, std::vector<Vec3>& force,
                           std::vector<Vec3>& shear) const;

 private:
  template <class Velocity>
  void accumulate(const Velocity& velocity, int n_spheres, double viscosity, std::vector<Vec3>& force,
                  std::vector<Vec3>& shear) const;
};

// include_walls: add the sphere-wall pairs (for no-slip walls).
ViscousShear build_viscous_shear(const Mesh& mesh, const CellGeometry& cells, const FacetGeometry& facets,
                                 const Packing& packing, bool include_walls);

}  // namespace pfv
