// Mean fluid velocity of each pore cell from the throat fluxes, for output (YADE's
// getCellVelocity, averageVelocity, VTK files); computed on demand, never by the step.
//
// For a divergence-free velocity field the volume integral of v over the pore equals the sum,
// over the pore's boundary, of x (v . n) dS; the solid surfaces carry no flux, so only the
// throats contribute, each with its flux q_f times the point where it is crossed. That point is
// taken where the throat's axis (the line of the two pore centres it joins, thesis 3.2, which
// is perpendicular to the facet) pierces the facet's plane: the throat's cross-section lies in
// that plane. Positions are measured from the cell's own centre, so that a pore which gains or
// loses volume (net flux not zero) does not get a velocity from its position in space:
//   v_c = (1 / V_f,c) * sum_f q_f (X_f - P_c),   q_f = k_f (p_c - p_f)  (leaving c).
// Both cells of a throat see it crossed at the same X_f, so sum_c V_f,c v_c = sum_f q_f (P_b -
// P_a) whatever X_f is: the Darcy flux times the length along a permeameter.
#pragma once
#include <vector>

#include "triangulation/pore_geometry.hpp"

namespace pfv {

// One velocity per cell; zero for a cell without fluid volume. centre: the sphere centres (the
// facets' planes pass through them).
std::vector<Vec3> mean_cell_velocities(const CellGeometry& cells, const FacetGeometry& facets,
                                       const std::vector<double>& conductance, const std::vector<double>& pressure,
                                       const std::vector<Vec3>& centre, int n_spheres);

}  // namespace pfv
