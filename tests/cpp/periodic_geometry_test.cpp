// Pore and throat geometry of periodic meshes: the walled mesh's formulas on images, with each
// neighbour's power centre translated by its period (pore_geometry.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <stdexcept>
#include <tuple>

#include "periodic_packings.hpp"
#include "triangulation/periodic_triangulation.hpp"
#include "triangulation/pore_geometry.hpp"

using namespace pfv;
using pfv::test::diagonal;
using pfv::test::PeriodicPacking;
using pfv::test::random_periodic;

namespace {

struct Geometry {
  CellGeometry cells;
  FacetGeometry facets;
};

Geometry geometry_of(const PeriodicMesh& m) {
  static const BoxWalls no_walls{};
  const Packing pk{m.image_centre, m.image_radius, no_walls, &m.cell.h};
  Geometry g;
  g.cells = compute_cell_geometry(m.mesh, pk);
  g.facets = compute_facet_geometry(m.mesh, g.cells, pk, false);
  return g;
}

// The throats as (hydraulic radius, length, fluid area), sorted: what a translation of the whole
// packing, or another choice of the same lattice's cell vectors, leaves unchanged.
std::vector<std::tuple<double, double, double>> sorted_throats(const FacetGeometry& f) {
  std::vector<std::tuple<double, double, double>> out;
  for (int k = 0; k < f.size(); ++k) out.emplace_back(f.hydraulic_radius[k], f.length[k], f.fluid_area[k]);
  std::sort(out.begin(), out.end());
  return out;
}

void expect_same_throats(const FacetGeometry& a, const FacetGeometry& b, double length) {
  const auto x = sorted_throats(a), y = sorted_throats(b);
  ASSERT_EQ(x.size(), y.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    EXPECT_NEAR(std::get<0>(x[k]), std::get<0>(y[k]), 1e-9 * length) << "throat " << k;
    EXPECT_NEAR(std::get<1>(x[k]), std::get<1>(y[k]), 1e-9 * length) << "throat " << k;
    EXPECT_NEAR(std::get<2>(x[k]), std::get<2>(y[k]), 1e-9 * length * length) << "throat " << k;
  }
}

void expect_closed_cells(const PeriodicMesh& m, const Geometry& g, bool distinct_centres = true) {
  const FacetGeometry& f = g.facets;
  ASSERT_EQ(static_cast<int>(f.translation.size()), f.size());
  // Every facet is stored once, two-sided, and find_facet finds it from both sides.
  EXPECT_EQ(f.size(), 2 * m.n_cells());
  for (int c = 0; c < m.n_cells(); ++c) {
    Vec3 outward = Vec3::Zero();
    double scale = 0;
    for (int l = 0; l < 4; ++l) {
      const int k = find_facet(f, m.mesh, c, l);
      ASSERT_GE(k, 0) << "cell " << c << " facet " << l;
      ASSERT_GE(f.cell[k][1], 0);
      const bool first = f.cell[k][0] == c && f.local[k][0] == l;
      EXPECT_TRUE(first || (f.cell[k][1] == c && f.local[k][1] == l));
      outward += first ? f.area_vector[k] : Vec3(-f.area_vector[k]);
      scale = std::max(scale, f.area_vector[k].norm());
      if (distinct_centres) {
        EXPECT_GT(f.length[k], 0) << "cell " << c << " facet " << l;
      }
    }
    EXPECT_LT(outward.norm(), 1e-12 * scale) << "cell " << c;
  }
  for (int k = 0; k < f.size(); ++k) {
    // The length joins the two power centres, the second one translated into place.
    const Vec3 d = g.cells.power_centre[f.cell[k][1]] + f.translation[k] - g.cells.power_centre[f.cell[k][0]];
    EXPECT_NEAR(f.length[k], d.norm(), 1e-12 * (1 + d.norm()));
  }
}

}  // namespace

TEST(PeriodicGeometry, CellsAreClosedAndTheFluidFillsWhatTheSpheresLeave) {
  Eigen::Matrix3d sheared = diagonal(1.0, 1.1, 0.9);
  sheared(0, 1) = 0.3;
  for (const Eigen::Matrix3d& h : {diagonal(1.0, 1.3, 0.8), sheared}) {
    const auto p = random_periodic(150, 21, h, 0.05, 0.1);
    PeriodicTriangulation tri;
    const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
    const Geometry g = geometry_of(m);
    expect_closed_cells(m, g, true);
    double total = 0, fluid = 0, solid = 0;
    for (int c = 0; c < m.n_cells(); ++c) {
      total += g.cells.volume[c];
      fluid += g.cells.fluid_volume[c];
    }
    for (double r : p.radius) solid += 4.0 / 3.0 * std::numbers::pi * r * r * r;
    EXPECT_NEAR(total, p.cell.volume(), 1e-12 * p.cell.volume());
    EXPECT_NEAR(fluid, p.cell.volume() - solid, 1e-10 * p.cell.volume());
  }
}

TEST(PeriodicGeometry, ThinCellsAndOneSphereCells) {
  // Thinner than the spacing: cells hold two images of one sphere. One sphere per cell: every
  // vertex is an image of it, and the throats inside a cube of the lattice have zero length.
  const auto thin = random_periodic(30, 22, diagonal(1, 1, 0.08), 0.03, 0.04);
  const auto one = PeriodicPacking{{Vec3(0.5, 0.5, 0.5)}, {0.3}, PeriodicCell{diagonal(1, 1, 1)}};
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(thin.centre, thin.radius, thin.cell);
  int repeated = 0;
  for (int c = 0; c < m.n_cells(); ++c) {
    std::set<int> spheres;
    for (int v : m.mesh.cell_vertices[c]) spheres.insert(m.image_sphere[v]);
    repeated += spheres.size() < 4;
  }
  EXPECT_GT(repeated, 0);
  expect_closed_cells(m, geometry_of(m), true);
  const PeriodicMesh& m1 = tri.build(one.centre, one.radius, one.cell);
  expect_closed_cells(m1, geometry_of(m1), false);
}

TEST(PeriodicGeometry, ThroatsDoNotDependOnTheCellsChoiceOrPlace) {
  const auto p = random_periodic(100, 23, diagonal(1, 1, 1), 0.05, 0.1);
  PeriodicTriangulation tri;
  const Geometry reference = geometry_of(tri.build(p.centre, p.radius, p.cell));
  auto moved = p.centre;
  for (Vec3& x : moved) x += Vec3(0.37, -0.61, 0.12);
  expect_same_throats(reference.facets, geometry_of(tri.build(moved, p.radius, p.cell)).facets, 1.0);
  PeriodicCell sheared = p.cell;
  sheared.h.col(2) += p.cell.h.col(0) - p.cell.h.col(1);  // the same lattice
  expect_same_throats(reference.facets, geometry_of(tri.build(p.centre, p.radius, sheared)).facets, 1.0);
}

TEST(PeriodicGeometry, APeriodicMeshNeedsItsPeriod) {
  const auto p = random_periodic(20, 24, diagonal(1, 1, 1), 0.05, 0.1);
  PeriodicTriangulation tri;
  const PeriodicMesh& m = tri.build(p.centre, p.radius, p.cell);
  static const BoxWalls no_walls{};
  const Packing pk{m.image_centre, m.image_radius, no_walls};
  const CellGeometry cells = compute_cell_geometry(m.mesh, pk);
  EXPECT_THROW(compute_facet_geometry(m.mesh, cells, pk, false), std::invalid_argument);
}
