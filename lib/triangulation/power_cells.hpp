// Volumes of the power (radical Voronoi) cells of the spheres, from the regular triangulation:
// the power cell of sphere v is bounded by one face per edge (v, w), the polygon of the power
// centres of the cells around that edge, which lies in the radical plane of v and w (for a wall,
// in the wall plane: power centres of wall cells lie on the walls). Its volume is the sum over
// the edges of the pyramids from v's centre to those faces (signed by the side of the plane the
// centre lies on). YADE's compTessVolumes / volume(id).
#pragma once
#include <vector>

#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct PowerCellVolumes {
  std::vector<double> volume;  // per sphere; 0 for a hidden sphere
  // Spheres with an edge whose ring of pore cells is open (a cell left out of the mesh, two
  // facing walls): their volume misses that face's pyramid.
  std::vector<int> incomplete;
};

// cells.power_centre must belong to the same positions as packing.
PowerCellVolumes power_cell_volumes(const Mesh& mesh, const CellGeometry& cells, const Packing& packing);

}  // namespace pfv
