// Topology of the regular triangulation, flattened into plain arrays.
//
// Vertices 0..n_spheres-1 are the spheres in input order; vertex n_spheres + w is wall w.
// Only "pore" cells are kept: finite cells with at least one sphere vertex and no two
// walls facing each other. Neighbour -1 means no pore cell across that facet. Cells are
// numbered breadth-first over their adjacency, so that neighbouring cells have near numbers
// (regular_triangulation.cpp).
#pragma once
#include <array>
#include <vector>

namespace pfv {

struct Mesh {
  int n_spheres = 0;
  std::vector<std::array<int, 4>> cell_vertices;
  std::vector<std::array<int, 4>> cell_neighbours;  // across the facet opposite vertex k
  std::vector<int> hidden_spheres;                  // spheres absent from the triangulation

  int n_cells() const { return static_cast<int>(cell_vertices.size()); }
  bool is_wall(int v) const { return v >= n_spheres; }
  int wall_of(int v) const { return v - n_spheres; }
};

}  // namespace pfv
