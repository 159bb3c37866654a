// The regular triangulation of an infinite periodic packing, one period of it.
//
// Every class of cells equal up to a lattice translation appears once. A cell's vertices are
// images: sphere image_sphere[v] translated by image_offset[v] periods, at image_centre[v]
// (images 0..n_spheres-1 are the spheres themselves, wrapped into the cell). So the geometry of
// a cell is read from image_centre as that of an ordinary mesh's from the centres. Across each
// facet lies another stored cell translated by mesh.neighbour_shift periods; mesh.cell_mirror
// gives the facet's local index in that neighbour: in a thin cell one cell may lie across two
// facets of another (through two periods), which only the mirror tells apart, and a cell may hold
// two images of one sphere. (A cell is never its own neighbour: a tetrahedron with two facets
// that are translates of each other has three collinear vertices.)
#pragma once
#include <array>
#include <vector>

#include "triangulation/mesh.hpp"
#include "triangulation/periodic_cell.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

struct PeriodicMesh {
  // mesh.n_spheres is the number of images: a periodic mesh has no wall vertices, and every
  // neighbour is a cell (never -1).
  Mesh mesh;
  int n_spheres = 0;
  // Per sphere, the periods that wrapped its centre into the cell: image v of sphere s lies at
  // centre[s] + h (wrap[s] + image_offset[v]), which follows the sphere as it moves.
  std::vector<Offset> wrap;
  std::vector<int> image_sphere;
  std::vector<Offset> image_offset;
  std::vector<Vec3> image_centre;
  std::vector<double> image_radius;
  PeriodicCell cell;
  double margin = 0;  // how far beyond the cell the images reached

  int n_cells() const { return mesh.n_cells(); }
  int n_images() const { return static_cast<int>(image_sphere.size()); }
};

}  // namespace pfv
