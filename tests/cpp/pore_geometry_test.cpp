// Geometry on hand-computable configurations and global identities of the pore partition.
#include "triangulation/pore_geometry.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "test_packings.hpp"
#include "triangulation/regular_triangulation.hpp"

using namespace pfv;

namespace {

struct Built {
  RegularTriangulation tri;
  CellGeometry cells;
  FacetGeometry facets;
};

Built build(const test::TestPacking& p, bool slip = true) {
  Built b;
  const Mesh& mesh = b.tri.build(p.centre, p.radius, p.walls);
  const Packing pk{p.centre, p.radius, p.walls};
  b.cells = compute_cell_geometry(mesh, pk);
  b.facets = compute_facet_geometry(mesh, b.cells, pk, slip);
  return b;
}

// A regular tetrahedron of unit spheres (edge 2*sqrt(2)) in the middle of a box.
test::TestPacking regular_tetrahedron() {
  test::TestPacking p;
  p.walls.coord = {-4, 4, -4, 4, -4, 4};
  p.centre = {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)};
  p.radius = {1, 1, 1, 1};
  return p;
}

}  // namespace

TEST(PoreGeometry, RegularTetrahedronCell) {
  const auto p = regular_tetrahedron();
  const Built b = build(p);
  const Mesh& mesh = b.tri.mesh();
  int interior = -1;
  for (int c = 0; c < mesh.n_cells(); ++c)
    if (b.cells.shape[c].n_walls == 0) interior = c;
  ASSERT_GE(interior, 0);
  const double omega = 3 * std::acos(1.0 / 3.0) - M_PI;  // solid angle at a vertex
  EXPECT_NEAR(b.cells.volume[interior], 8.0 / 3.0, 1e-13);
  EXPECT_NEAR(b.cells.fluid_volume[interior], 8.0 / 3.0 - 4 * omega / 3.0, 1e-13);
  EXPECT_NEAR(b.cells.power_centre[interior].norm(), 0.0, 1e-13);  // equal radii: circumcentre

  // Its four facets: equilateral triangles of side 2 sqrt(2), three 60-degree sectors each.
  int seen = 0;
  for (int f = 0; f < b.facets.size(); ++f) {
    if (b.facets.cell[f][0] != interior && b.facets.cell[f][1] != interior) continue;
    ++seen;
    EXPECT_NEAR(b.facets.area_vector[f].norm(), 2 * std::sqrt(3.0), 1e-13);
    for (double a : b.facets.sector_area[f]) EXPECT_NEAR(a, M_PI / 6, 1e-13);
    EXPECT_NEAR(b.facets.fluid_area[f], 2 * std::sqrt(3.0) - M_PI / 2, 1e-13);
  }
  EXPECT_EQ(seen, 4);
}

TEST(PoreGeometry, CellsTileTheBoxAndFluidVolumeIsTheVoid) {
  const auto p = test::random_packing(400, 7);
  const Built b = build(p);
  EXPECT_TRUE(b.tri.mesh().hidden_spheres.empty());
  const double total = std::accumulate(b.cells.volume.begin(), b.cells.volume.end(), 0.0);
  EXPECT_NEAR(total, 1.0, 1e-12);
  double solid = 0;
  for (double r : p.radius) solid += 4.0 / 3.0 * M_PI * r * r * r;
  const double fluid = std::accumulate(b.cells.fluid_volume.begin(), b.cells.fluid_volume.end(), 0.0);
  EXPECT_NEAR(fluid, 1.0 - solid, 1e-12);
}

TEST(PoreGeometry, ThroatQuantitiesArePositiveAndFinite) {
  const auto p = test::random_packing(300, 3);
  const Built b = build(p);
  for (int f = 0; f < b.facets.size(); ++f) {
    if (b.facets.cell[f][1] < 0) continue;
    EXPECT_TRUE(std::isfinite(b.facets.hydraulic_radius[f]));
    EXPECT_GE(b.facets.fluid_area[f], 0.0);
    EXPECT_GE(b.facets.length[f], 0.0);
    EXPECT_GE(b.facets.hydraulic_radius[f], 0.0);
  }
}

TEST(PoreGeometry, EachCellIsAClosedSurface) {
  // Facet area vectors (out of the cell) plus the wall footprints (out of the box) sum to 0.
  const auto p = test::random_packing(200, 11);
  RegularTriangulation tri;
  const Mesh& mesh = tri.build(p.centre, p.radius, p.walls);
  const Packing pk{p.centre, p.radius, p.walls};
  for (int c = 0; c < mesh.n_cells(); ++c) {
    Vec3 sum = Vec3::Zero();
    for (int l = 0; l < 4; ++l) {
      std::array<int, 3> f;
      for (int i = 0, k = 0; i < 4; ++i)
        if (i != l) f[k++] = mesh.cell_vertices[c][i];
      sum += facet_area_vector(mesh, f, mesh.cell_vertices[c][l], pk);
    }
    for (const Vec3& w : wall_footprints(mesh, c, pk)) sum += w;
    EXPECT_LT(sum.norm(), 1e-12) << "cell " << c;
  }
}

TEST(PoreGeometry, WallRadiusDoesNotLeakIntoGeometry) {
  // The combinatorics come from a finite fictitious radius; moving the packing far from the
  // origin must not change the geometry (no R^2-sized cancellation).
  auto p = test::random_packing(150, 5);
  const Built a = build(p);
  for (auto& x : p.centre) x += Vec3(1000, -2000, 500);
  for (int w = 0; w < 6; ++w) p.walls.coord[w] += Vec3(1000, -2000, 500)[wall_axis(w)];
  const Built b = build(p);
  ASSERT_EQ(a.cells.volume.size(), b.cells.volume.size());
  const double va = std::accumulate(a.cells.fluid_volume.begin(), a.cells.fluid_volume.end(), 0.0);
  const double vb = std::accumulate(b.cells.fluid_volume.begin(), b.cells.fluid_volume.end(), 0.0);
  EXPECT_NEAR(va, vb, 1e-9);
}
