// Mean fluid velocity of each pore cell from the throat fluxes, for output (YADE's
// getCellVelocity, averageVelocity, VTK files); computed on demand, never by the step.
//
// For a divergence-free velocity field the volume integral of v over the pore equals the sum,
// over the pore's boundary, of x (v . n) dS; the solid surfaces carry no flux, so only the
// throats contribute, each with its flux q_f times the point where it is crossed. That point is
// taken at the midpoint of the two pore centres the throat joins (the throat's axis, thesis
// 3.2), and positions are measured from the cell's own centre, so that a pore which gains or
// loses volume (net flux not zero) does not get a velocity from its position in space:
//   v_c = (1 / V_f,c) * sum_f q_f (P_f - P_c) / 2,   q_f = k_f (p_c - p_f)  (leaving c).
#pragma once
#include <vector>

#include "triangulation/pore_geometry.hpp"

namespace pfv {

// One velocity per cell; zero for a cell without fluid volume.
std::vector<Vec3> mean_cell_velocities(const CellGeometry& cells, const FacetGeometry& facets,
                                       const std::vector<double>& conductance, const std::vector<double>& pressure);

}  // namespace pfv
