// PeriodicTriangulation: one period of the regular triangulation of an infinite periodic packing,
// checked against what that triangulation must be (empty orthogonal spheres over all images, a
// tiling of the cell, consistent adjacency across periods) and against itself under the
// transformations that leave the infinite packing unchanged.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <stdexcept>

#include "periodic_packings.hpp"
#include "triangulation/periodic_triangulation.hpp"

using namespace pfv;
using pfv::test::diagonal;
using pfv::test::periodic_difference;
using pfv::test::PeriodicPacking;
using pfv::test::random_periodic;

namespace {

double cell_volume(const PeriodicMesh& m, int c) {
  const auto& v = m.mesh.cell_vertices[c];
  const Vec3& x0 = m.image_centre[v[0]];
  return std::abs((m.image_centre[v[1]] - x0).dot((m.image_centre[v[2]] - x0).cross(m.image_centre[v[3]] - x0))) / 6;
}

std::vector<double> sorted_volumes(const PeriodicMesh& m) {
  std::vector<double> out;
  for (int c = 0; c < m.n_cells(); ++c) out.push_back(cell_volume(m, c));
  std::sort(out.begin(), out.end());
  return out;
}

// The volumes of two triangulations of one infinite packing, cell by cell after sorting.
void expect_same_volumes(const std::vector<double>& a, const std::vector<double>& b, double scale) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(a[k], b[k], 1e-10 * scale) << "cell " << k;
}

struct ImageKey {
  int sphere;
  Offset offset;
  bool operator<(const ImageKey& o) const { return sphere != o.sphere ? sphere < o.sphere : offset < o.offset; }
  bool operator==(const ImageKey& o) const { return sphere == o.sphere && offset == o.offset; }
};

std::set<ImageKey> facet_images(const PeriodicMesh& m, int c, int local, const Offset& shift) {
  std::set<ImageKey> out;
  for (int k = 0; k < 4; ++k) {
    if (k == local) continue;
    const int v = m.mesh.cell_vertices[c][k];
    Offset o = m.image_offset[v];
    for (int a = 0; a < 3; ++a) o[a] += shift[a];
    out.insert({m.image_sphere[v], o});
  }
  return out;
}

// Everything one period of the infinite regular triangulation must satisfy.
void expect_periodic_triangulation(const PeriodicMesh& m, const PeriodicPacking& p) {
  const int n = static_cast<int>(p.centre.size());
  ASSERT_GT(m.n_cells(), 0);
  EXPECT_EQ(m.n_spheres, n);
  EXPECT_EQ(m.mesh.n_spheres, m.n_images());
  // Images 0..n-1 are the spheres wrapped into the cell; every image is a translate of one.
  for (int v = 0; v < m.n_images(); ++v) {
    const int s = m.image_sphere[v];
    ASSERT_TRUE(s >= 0 && s < n);
    if (v < n) {
      EXPECT_EQ(s, v);
    }
    const Vec3 wrapped = m.image_centre[s];
    const Vec3 f = p.cell.fractional(wrapped);
    if (v < n) {
      for (int a = 0; a < 3; ++a) EXPECT_TRUE(f[a] >= -1e-12 && f[a] < 1 + 1e-12) << "sphere " << s;
    }
    EXPECT_LT((m.image_centre[v] - wrapped - p.cell.translation(m.image_offset[v])).norm(), 1e-12);
    EXPECT_LT(periodic_difference(p.cell, wrapped, p.centre[s]).norm(), 1e-12);
    Offset o = m.image_offset[v];
    for (int a = 0; a < 3; ++a) o[a] += m.wrap[s][a];
    EXPECT_LT((m.image_centre[v] - p.centre[s] - p.cell.translation(o)).norm(), 1e-12);
    EXPECT_EQ(m.image_radius[v], p.radius[s]);
  }
  // The cells tile one period.
  double total = 0;
  for (int c = 0; c < m.n_cells(); ++c) total += cell_volume(m, c);
  EXPECT_NEAR(total, p.cell.volume(), 1e-10 * p.cell.volume());
  // Adjacency: the neighbour across a facet sees this cell across the mirrored facet, through the
  // opposite shift, and both see the same three images.
  for (int c = 0; c < m.n_cells(); ++c)
    for (int l = 0; l < 4; ++l) {
      const int j = m.mesh.cell_neighbours[c][l], lj = m.mesh.cell_mirror[c][l];
      ASSERT_TRUE(j >= 0 && j < m.n_cells() && lj >= 0 && lj < 4);
      const Offset t = m.mesh.neighbour_shift[c][l];
      EXPECT_EQ(m.mesh.cell_neighbours[j][lj], c);
      EXPECT_EQ(m.mesh.cell_mirror[j][lj], l);
      EXPECT_EQ(m.mesh.neighbour_shift[j][lj], (Offset{-t[0], -t[1], -t[2]}));
      EXPECT_EQ(facet_images(m, c, l, {0, 0, 0}), facet_images(m, j, lj, t)) << "cell " << c << " facet " << l;
    }
  // Empty orthogonal spheres: no image of any sphere within the two neighbouring periods has a
  // power distance below the cell's orthogonal radius (brute force, independent of CGAL).
  for (int c = 0; c < m.n_cells(); ++c) {
    const auto& v = m.mesh.cell_vertices[c];
    const Vec3& x0 = m.image_centre[v[0]];
    Eigen::Matrix3d a;
    Vec3 b;
    const double w0 = m.image_radius[v[0]] * m.image_radius[v[0]];
    for (int i = 1; i < 4; ++i) {
      const Vec3 q = m.image_centre[v[i]] - x0;
      a.row(i - 1) = 2 * q.transpose();
      b[i - 1] = q.squaredNorm() - m.image_radius[v[i]] * m.image_radius[v[i]] + w0;
    }
    const Vec3 centre = x0 + a.fullPivLu().solve(b);
    const double power = (centre - x0).squaredNorm() - w0;
    const double scale = std::max(1.0, std::abs(power));
    for (int s = 0; s < n; ++s)
      for (int i = -2; i <= 2; ++i)
        for (int j = -2; j <= 2; ++j)
          for (int k = -2; k <= 2; ++k) {
            const Vec3 y = m.image_centre[s] + p.cell.translation({i, j, k});
            const double d = (centre - y).squaredNorm() - p.radius[s] * p.radius[s];
            ASSERT_GE(d, power - 1e-9 * scale) << "cell " << c << " sphere " << s;
          }
  }
}

}  // namespace

TEST(PeriodicTriangulation, OnePeriodOfTheInfiniteTriangulationInACuboid) {
  const auto p = random_periodic(120, 1, diagonal(1.0, 1.3, 0.8), 0.05, 0.1);
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  expect_periodic_triangulation(m, p);
  EXPECT_TRUE(m.mesh.hidden_spheres.empty());
}

TEST(PeriodicTriangulation, OnePeriodOfTheInfiniteTriangulationInAShearedCell) {
  Eigen::Matrix3d h = diagonal(1.0, 1.1, 0.9);
  h(0, 1) = 0.35;  // the second cell vector leans along x
  h(2, 0) = -0.2;
  const auto p = random_periodic(120, 2, h, 0.05, 0.1);
  PeriodicTriangulation tri;
  expect_periodic_triangulation(tri.build(p.centre, p.radius, p.cell), p);
}

TEST(PeriodicTriangulation, DensePolydisperseAndThinCells) {
  // Near the densest random placement of these radii; then a cell one large sphere thick along z,
  // where a cell holds two images of one sphere.
  const auto dense = random_periodic(200, 3, diagonal(1, 1, 1), 0.05, 0.1);
  PeriodicTriangulation tri;
  expect_periodic_triangulation(tri.build(dense.centre, dense.radius, dense.cell), dense);
  const auto thin = random_periodic(40, 4, diagonal(1, 1, 0.25), 0.05, 0.1);
  expect_periodic_triangulation(tri.build(thin.centre, thin.radius, thin.cell), thin);
}

TEST(PeriodicTriangulation, SparsePackingsWidenTheMargin) {
  // Pores far larger than the spheres: the first margin (1.5 spacings) misses images that conflict
  // with some cells, and the build must notice and widen it.
  const auto p = random_periodic(12, 12, diagonal(1, 1, 1), 0.01, 0.02);
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  expect_periodic_triangulation(m, p);
  EXPECT_GT(m.margin, 1.5 * std::cbrt(1.0 / 12));
}

TEST(PeriodicTriangulation, CentresOutsideTheCellAreWrapped) {
  auto p = random_periodic(80, 5, diagonal(1, 1, 1), 0.05, 0.1);
  PeriodicTriangulation tri;
  const auto reference = sorted_volumes(tri.build(p.centre, p.radius, p.cell));
  std::mt19937 gen(6);
  std::uniform_int_distribution<int> period(-3, 3);
  for (Vec3& x : p.centre) x += p.cell.translation({period(gen), period(gen), period(gen)});
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  expect_same_volumes(reference, sorted_volumes(m), 1.0 / p.centre.size());
  expect_periodic_triangulation(m, p);
}

TEST(PeriodicTriangulation, ShiftingEverySphereChangesNoCell) {
  const auto p = random_periodic(100, 7, diagonal(1.2, 1, 1), 0.05, 0.1);
  PeriodicTriangulation tri;
  const auto reference = sorted_volumes(tri.build(p.centre, p.radius, p.cell));
  for (const Vec3& shift : {Vec3(0.31, -0.17, 0.55), Vec3(1e-9, 0, 0), Vec3(-0.6, 0.6, 0.999)}) {
    auto moved = p.centre;
    for (Vec3& x : moved) x += shift;
    expect_same_volumes(reference, sorted_volumes(tri.build(moved, p.radius, p.cell)), 1.0 / p.centre.size());
  }
}

TEST(PeriodicTriangulation, TwoByTwoByTwoCopiesHaveEightTimesTheCells) {
  const auto p = random_periodic(60, 8, diagonal(1, 1.1, 0.9), 0.05, 0.1);
  PeriodicTriangulation tri;
  const auto one = sorted_volumes(tri.build(p.centre, p.radius, p.cell));
  const PeriodicPacking big = pfv::test::tiled(p);
  const auto eight = sorted_volumes(tri.build(big.centre, big.radius, big.cell));
  std::vector<double> expected;
  for (double v : one) expected.insert(expected.end(), 8, v);
  expect_same_volumes(expected, eight, 1.0 / p.centre.size());
}

TEST(PeriodicTriangulation, ShearByOnePeriodIsTheSamePacking) {
  // h' = h with a whole period added to one cell vector spans the same lattice: the same infinite
  // packing, so the same cells.
  const auto p = random_periodic(100, 9, diagonal(1, 1, 1), 0.05, 0.1);
  PeriodicTriangulation tri;
  const auto reference = sorted_volumes(tri.build(p.centre, p.radius, p.cell));
  PeriodicCell sheared = p.cell;
  sheared.h.col(1) += p.cell.h.col(0);
  const PeriodicMesh& m = tri.build(p.centre, p.radius, sheared);
  expect_same_volumes(reference, sorted_volumes(m), 1.0 / p.centre.size());
  expect_periodic_triangulation(m, PeriodicPacking{p.centre, p.radius, sheared});
}

TEST(PeriodicTriangulation, SimpleCubicArray) {
  // Cospherical everywhere: every cube of the lattice is split into tetrahedra somehow, but they
  // tile it and the adjacency closes.
  PeriodicPacking p;
  p.cell.h = diagonal(3, 3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) {
        p.centre.emplace_back(i + 0.5, j + 0.5, k + 0.5);
        p.radius.push_back(0.5);
      }
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  expect_periodic_triangulation(m, p);
  const int cells = m.n_cells();
  // One sphere in a unit cell: the same lattice, split the same way in every cube.
  const PeriodicPacking one{{Vec3(0.5, 0.5, 0.5)}, {0.5}, PeriodicCell{diagonal(1, 1, 1)}};
  const PeriodicMesh& m1 = tri.build(one.centre, one.radius, one.cell);
  expect_periodic_triangulation(m1, one);
  EXPECT_EQ(m1.n_cells() * 27, cells);
}

TEST(PeriodicTriangulation, LocateFindsTheCellTranslateThatHoldsThePoint) {
  Eigen::Matrix3d h = diagonal(1, 1, 1);
  h(0, 2) = 0.4;
  const auto p = random_periodic(100, 10, h, 0.05, 0.1);
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> u(-2, 3);
  for (int k = 0; k < 500; ++k) {
    const Vec3 x(u(gen), u(gen), u(gen));
    const auto where = tri.locate(x);
    ASSERT_GE(where.cell, 0);
    const auto& v = m.mesh.cell_vertices[where.cell];
    const Vec3 t = p.cell.translation(where.shift);
    Eigen::Matrix3d e;
    for (int i = 1; i < 4; ++i) e.col(i - 1) = m.image_centre[v[i]] - m.image_centre[v[0]];
    const Vec3 bary = e.fullPivLu().solve(x - t - m.image_centre[v[0]]);
    EXPECT_GE(bary.minCoeff(), -1e-9) << "point " << k;
    EXPECT_LE(bary.sum(), 1 + 1e-9) << "point " << k;
  }
  EXPECT_EQ(tri.locate(Vec3(NAN, 0, 0)).cell, -1);
}

TEST(PeriodicTriangulation, RefusesBadInput) {
  PeriodicTriangulation tri;
  const PeriodicCell unit{diagonal(1, 1, 1)};
  EXPECT_THROW(tri.build({}, {}, unit), std::invalid_argument);
  EXPECT_THROW(tri.build({Vec3(0.5, 0.5, 0.5)}, {0.1, 0.2}, unit), std::invalid_argument);
  EXPECT_THROW(tri.build({Vec3(NAN, 0.5, 0.5)}, {0.1}, unit), std::invalid_argument);
  EXPECT_THROW(tri.build({Vec3(0.5, 0.5, 0.5)}, {0.0}, unit), std::invalid_argument);
  EXPECT_THROW(tri.build({Vec3(0.5, 0.5, 0.5)}, {0.1}, PeriodicCell{diagonal(1, 0, 1)}), std::invalid_argument);
  Eigen::Matrix3d flat = diagonal(1, 1, 1);
  flat.col(2) = flat.col(0) + flat.col(1);
  EXPECT_THROW(tri.build({Vec3(0.5, 0.5, 0.5)}, {0.1}, PeriodicCell{flat}), std::invalid_argument);
}
