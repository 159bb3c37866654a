// Regular (weighted Delaunay) triangulation of a sphere packing inside six walls.
//
// Weights are squared radii; each wall enters as a fictitious sphere whose radius is
// kWallRadiusFactor times the box size and whose surface lies on the wall plane. CGAL
// decides the combinatorics with exact predicates; nothing geometric is taken from CGAL
// afterwards (see pore_geometry.hpp for why the walls are treated as planes there).
#pragma once
#include <memory>
#include <vector>

#include "triangulation/box_walls.hpp"
#include "triangulation/mesh.hpp"
#include "triangulation/vec3.hpp"

namespace pfv {

class RegularTriangulation {
 public:
  static constexpr double kWallRadiusFactor = 1e6;  // thesis, section 3.5 (R = 1e6 l0)

  RegularTriangulation();
  ~RegularTriangulation();
  RegularTriangulation(RegularTriangulation&&) noexcept;
  RegularTriangulation& operator=(RegularTriangulation&&) noexcept;
  RegularTriangulation(const RegularTriangulation&) = delete;
  RegularTriangulation& operator=(const RegularTriangulation&) = delete;

  // Rebuilds from scratch (bulk insertion with spatial sorting) and returns the pore mesh.
  const Mesh& build(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls);

  const Mesh& mesh() const { return mesh_; }

  // Index of the pore cell containing x, or -1 if x lies in no pore cell.
  int locate(const Vec3& x) const;

  // locate() of every point, each walk started from the cell of the previous point found. CGAL's
  // walk from an arbitrary cell crosses O(N^(1/3)) cells; points listed in a spatially coherent
  // order (the cells of another mesh of the same packing, by index: they are numbered
  // breadth-first, mesh.hpp) are found a few cells from the last one.
  std::vector<int> locate_all(const std::vector<Vec3>& points) const;

  // Pairs of spheres with one centre inside the other sphere: neighbours in the
  // triangulation, and each hidden sphere with the sphere that hides it.
  std::vector<std::pair<int, int>> centres_inside_neighbours(const std::vector<Vec3>& centres,
                                                             const std::vector<double>& radii) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  Mesh mesh_;
  BoxWalls walls_;
};

}  // namespace pfv
