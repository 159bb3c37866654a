// Topology of the regular triangulation, flattened into plain arrays.
//
// Vertices 0..n_spheres-1 are the spheres in input order; vertex n_spheres + w is wall w. In a
// periodic mesh (periodic_mesh.hpp) the vertices are images of the spheres, there are no walls,
// and each neighbour is a cell translated by whole periods.
// Only "pore" cells are kept: finite cells with at least one sphere vertex and no two
// walls facing each other. Neighbour -1 means no pore cell across that facet. Cells are
// numbered breadth-first over their adjacency, so that neighbouring cells have near numbers
// (regular_triangulation.cpp).
#pragma once
#include <array>
#include <vector>

namespace pfv {

using Offset = std::array<int, 3>;  // a lattice translation, in periods along each cell vector

struct Mesh {
  int n_spheres = 0;
  std::vector<std::array<int, 4>> cell_vertices;
  std::vector<std::array<int, 4>> cell_neighbours;  // across the facet opposite vertex k
  std::vector<int> hidden_spheres;                  // spheres absent from the triangulation
  // Periodic meshes only (empty otherwise): across facet k, the local index of the facet in the
  // neighbour (another cell may lie across two facets, through two periods), and its translation.
  std::vector<std::array<int, 4>> cell_mirror;
  std::vector<std::array<Offset, 4>> neighbour_shift;

  int n_cells() const { return static_cast<int>(cell_vertices.size()); }
  bool periodic() const { return !cell_mirror.empty(); }
  bool is_wall(int v) const { return v >= n_spheres; }
  int wall_of(int v) const { return v - n_spheres; }
};

}  // namespace pfv
