// RegularTriangulation::locate_all, the hinted walk of a remesh, against one locate() per point.
#include <gtest/gtest.h>

#include <random>

#include "test_packings.hpp"
#include "triangulation/regular_triangulation.hpp"

using namespace pfv;

TEST(PointLocation, LocateAllFindsTheCellsLocateFinds) {
  const auto p = test::random_packing(400, 7);
  RegularTriangulation tri;
  const Mesh& mesh = tri.build(p.centre, p.radius, p.walls);
  // Random points in and around the box (outside: -1 from both), then the centroids of the cells
  // with four sphere vertices (strictly inside their cell) in index order, the order a remesh queries.
  std::mt19937 gen(3);
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  std::vector<Vec3> points;
  for (int k = 0; k < 3000; ++k) points.emplace_back(u(gen), u(gen), u(gen));
  std::vector<int> interior;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    Vec3 s = Vec3::Zero();
    bool spheres_only = true;
    for (const int v : mesh.cell_vertices[c]) {
      spheres_only &= v < mesh.n_spheres;
      if (v < mesh.n_spheres) s += p.centre[v];
    }
    if (!spheres_only) continue;
    interior.push_back(c);
    points.push_back(s / 4);
  }
  const std::vector<int> all = tri.locate_all(points);
  ASSERT_EQ(all.size(), points.size());
  int outside = 0, found = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    EXPECT_EQ(all[k], tri.locate(points[k])) << "point " << k;
    outside += all[k] < 0;
    found += all[k] >= 0;
  }
  for (std::size_t k = 0; k < interior.size(); ++k) EXPECT_EQ(all[3000 + k], interior[k]);
  EXPECT_GT(outside, 500);  // the shell around the box is in no pore cell
  EXPECT_GT(found, 2000);
  EXPECT_TRUE(tri.locate_all({}).empty());
}
