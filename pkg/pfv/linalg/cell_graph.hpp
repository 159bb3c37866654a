// What the reuse of an elimination order across remeshes (ordering_reuse.hpp) needs of a
// tetrahedral mesh and of its unknowns, as plain arrays: each cell's four vertices (spheres
// 0..n_spheres - 1, then walls), its four neighbours across its facets (-1: none), and the cell
// of each unknown. A view: the arrays belong to the caller and must outlive it.
#pragma once
#include <array>
#include <span>

namespace pfv {

struct CellGraph {
  int n_spheres = 0;
  std::span<const std::array<int, 4>> vertices;    // per cell
  std::span<const std::array<int, 4>> neighbours;  // per cell
  std::span<const int> unknown_cell;               // per unknown

  int n_cells() const { return static_cast<int>(vertices.size()); }
  int n_unknowns() const { return static_cast<int>(unknown_cell.size()); }
};

}  // namespace pfv
