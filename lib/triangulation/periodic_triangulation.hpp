// Regular triangulation of a periodic sphere packing in a cuboid or sheared cell.
//
// CGAL's Periodic_3_regular_triangulation_3 (CGAL 5.5) covers the cubic flat torus only: one
// period on all three axes, no shear, and weights below a bound set by the period. YADE's cells
// are cuboids and get sheared, so the general construction is used: the ordinary regular
// triangulation of the spheres and of their images within a margin of the cell, from which one
// representative of every class of cells equal up to a lattice translation is kept, the one whose
// smallest vertex (by sphere, then offset) is a sphere of the cell itself. A kept cell is a cell of
// the infinite periodic triangulation when its orthogonal sphere, grown by the largest weight, lies
// inside the region the images cover (no image missing from the margin could conflict with it);
// the kept cells are all the classes when their volumes add up to the cell's. Either test failing
// widens the margin and builds again.
#pragma once
#include <memory>
#include <vector>

#include "triangulation/periodic_mesh.hpp"

namespace pfv {

class PeriodicTriangulation {
 public:
  PeriodicTriangulation();
  ~PeriodicTriangulation();
  PeriodicTriangulation(PeriodicTriangulation&&) noexcept;
  PeriodicTriangulation& operator=(PeriodicTriangulation&&) noexcept;
  PeriodicTriangulation(const PeriodicTriangulation&) = delete;
  PeriodicTriangulation& operator=(const PeriodicTriangulation&) = delete;

  // Rebuilds from scratch. Centres anywhere (wrapped into the cell here); radii > 0; the cell
  // non-degenerate. Throws std::invalid_argument on bad input, std::runtime_error if no margin
  // up to kMaxMarginWidths widths of the cell gives a consistent triangulation.
  const PeriodicMesh& build(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                            const PeriodicCell& cell);

  const PeriodicMesh& mesh() const { return mesh_; }

  struct Location {
    int cell = -1;   // the stored cell, -1 if none (no mesh yet)
    Offset shift{};  // x lies in that cell translated by shift periods
  };
  Location locate(const Vec3& x) const;

  // The margin is grown from its first guess by this factor per attempt, up to this many cell
  // widths: a triangulation that needs more is not a packing (a few spheres in a huge cell).
  static constexpr double kMarginGrowth = 1.6;
  static constexpr double kMaxMarginWidths = 3.0;

 private:
  struct Impl;
  bool try_build(const std::vector<double>& radii, double margin);

  std::unique_ptr<Impl> impl_;
  PeriodicMesh mesh_;
};

}  // namespace pfv
