// Pore geometry of the regular triangulation: cells (pores) and facets (throats).
//
// Walls are treated in the limit of an infinite fictitious radius. A wall vertex is then a
// direction (-n, out of the box) rather than a point: a cell with wall vertices is the prism
// swept from its sphere centres towards the walls, and its power centre lies on the wall
// planes. This is the thesis' "prismatic" boundary pore (section 2.3 of the spec) made exact,
// and it avoids the cancellation of R^2-sized terms that a finite huge sphere would cause.
//
// Per cell: total volume, fluid volume, power centre. Per facet: area vector, fluid area,
// hydraulic radius R_h = phi/gamma, length L between power centres, the sphere sectors A^k
// and wetted areas gamma^k of its three vertices (walls included only for no-slip).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "triangulation/box_walls.hpp"
#include "triangulation/mesh.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

// A cell's vertices with spheres first, then walls (as wall indices 0..5).
struct CellShape {
  std::int8_t n_walls = 0;
  // The sign of oriented_cell_volume when the mesh was built (0: flat then). Motion that
  // flips it has turned the cell inside out: the mesh no longer describes the pore space.
  std::int8_t orientation = 0;
  std::array<int, 4> v{};  // v[0..3-n_walls] sphere ids, the rest wall indices
};

struct CellGeometry {
  std::vector<CellShape> shape;
  std::vector<double> volume;        // total (tetrahedron or wall prism)
  std::vector<double> fluid_volume;  // volume minus sphere sectors, floored at 0
  std::vector<Vec3> power_centre;
};

struct FacetGeometry {
  // Facet f separates cell[f][0] from cell[f][1] (-1: no pore cell on that side) and is
  // the facet opposite local vertex local[f][0] of cell[f][0].
  std::vector<std::array<int, 2>> cell;
  std::vector<std::array<int, 2>> local;
  std::vector<std::array<int, 3>> vertex;  // mesh vertex ids (walls: n_spheres + w)
  std::vector<Vec3> area_vector;           // |S| times the unit normal from cell 0 to cell 1
  std::vector<double> fluid_area;
  std::vector<double> length;  // |P_0 P_1|; 0 for a one-sided facet
  std::vector<double> hydraulic_radius;
  std::vector<std::array<double, 3>> sector_area;  // A^k, scaled down if they exceed the facet
  std::vector<std::array<double, 3>> wetted_area;  // gamma^k
  // Periodic meshes only (else empty): where cell[f][1] lies as seen from cell[f][0], the
  // translation h * shift of the stored cell (its power centre and vertices move with it).
  std::vector<Vec3> translation;

  int size() const { return static_cast<int>(cell.size()); }
};

struct Packing {
  const std::vector<Vec3>& centre;  // per mesh vertex (in a periodic mesh, per image)
  const std::vector<double>& radius;
  const BoxWalls& walls;                    // unused by a periodic mesh
  const Eigen::Matrix3d* period = nullptr;  // a periodic mesh's cell vectors (periodic_cell.hpp)
};

// Where the neighbour across facet 'local' of 'cell' lies: the stored cell translated by this
// (zero but in a periodic mesh).
Vec3 neighbour_translation(const Mesh& mesh, const Packing& packing, int cell, int local);

CellShape make_cell_shape(const Mesh& mesh, int cell);

// Total volume of a cell for the current positions, signed by the orientation of its vertices
// (the sign of the triple product; for wall cells, of the sphere part projected on the wall).
double oriented_cell_volume(const CellShape& s, const std::vector<Vec3>& centre, const BoxWalls& walls);
// oriented_cell_volume in the orientation the cell had when the mesh was built: what dV/dt
// differentiates. It turns negative when motion turns the cell inside out, and that sign is what
// keeps the mesh conservative until the next remesh: the signed volumes of the cells still sum to
// the volume they tile, so the volume rates sum to the rate of change of that volume (the motion
// of the walls) however the spheres move. Cells flat when built have no orientation: |volume|.
inline double cell_volume(const CellShape& s, const std::vector<Vec3>& centre, const BoxWalls& walls) {
  const double oriented = oriented_cell_volume(s, centre, walls);
  return s.orientation != 0 ? s.orientation * oriented : std::abs(oriented);
}

CellGeometry compute_cell_geometry(const Mesh& mesh, const Packing& packing);

FacetGeometry compute_facet_geometry(const Mesh& mesh, const CellGeometry& cells, const Packing& packing,
                                     bool slip_boundary);

// The facet of the current geometry opposite local vertex 'local' of 'cell' (-1 if none): each
// facet is stored once, from its lower-numbered pore cell, facets of a cell contiguous.
int find_facet(const FacetGeometry& facets, const Mesh& mesh, int cell, int local);

// The solid surface of the half throat on the side of 'cell': the part of the throat
// bipyramid between the facet opposite its local vertex 'local' and the cell's power centre.
// Entry k is for vertex k of the facet (the cell's vertices without 'local', in order): the
// spherical triangle of a sphere; for a wall, its area in the half throat if solid_wall[w]
// (else 0). Signed half pyramids are counted as compute_facet_geometry counts them, floored at 0.
std::array<double, 3> half_throat_wetted_area(const Mesh& mesh, const CellGeometry& cells, const Packing& packing,
                                              int cell, int local, const std::array<bool, kWallCount>& solid_wall);

// Projected area of a cell on each of its walls, as outward force vectors per unit
// pressure (the wall part of the force cache). Entry k is for local vertex k of the cell;
// sphere vertices get zero.
std::array<Vec3, 4> wall_footprints(const Mesh& mesh, int cell, const Packing& packing);

// The polygon of a facet (triangle, wall trapezoid or wall rectangle) as an area vector
// oriented away from the vertex 'opposite' of the owning cell.
Vec3 facet_area_vector(const Mesh& mesh, const std::array<int, 3>& facet, int opposite, const Packing& packing);

}  // namespace pfv
