// Geometry asked of single cells and throats after a step (constrictions, power cells, half
// throats, facet lookup, mean cell velocities), and the cell conditions a remesh makes or carries
// (flat cells, interpolated blocked cells, the mesh-only remesh) and the pressure profile of a wall.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/model/cell_velocity.hpp"
#include "test_packings.hpp"
#include "triangulation/constriction.hpp"
#include "triangulation/power_cells.hpp"

using namespace pfv;
using test::permeameter;

TEST(Constriction, ThreeEqualSpheresLeaveTheCircleAtTheCentroid) {
  // Side s, radius r: the gap circle is centred at the centroid, s / sqrt(3) from each centre.
  const double s = 1.0, r = 0.4;
  const std::vector<Vec3> c{Vec3(0, 0, 0.3), Vec3(s, 0, 0.3), Vec3(0.5 * s, std::sqrt(0.75) * s, 0.3)};
  const std::vector<double> radius(3, r);
  BoxWalls walls;
  walls.coord = {-5, 5, -5, 5, -5, 5};
  Mesh mesh;
  mesh.n_spheres = 3;
  const Constriction k = throat_constriction(mesh, {0, 1, 2}, Packing{c, radius, walls});
  EXPECT_NEAR(k.radius, s / std::sqrt(3.0) - r, 1e-14);
  EXPECT_LT((k.centre - (c[0] + c[1] + c[2]) / 3.0).norm(), 1e-14);
}

TEST(Constriction, TwoSpheresAndAWall) {
  // Spheres of radius r at x = +-d, height h above the ymin wall: by symmetry the circle sits at
  // x = 0 touching the wall, rho = (d^2 + h^2 - r^2) / (2 (h + r)).
  const double d = 0.3, h = 0.25, r = 0.2;
  const std::vector<Vec3> c{Vec3(0.5 - d, h, 0.5), Vec3(0.5 + d, h, 0.5)};
  const std::vector<double> radius(2, r);
  BoxWalls walls;
  walls.coord = {0, 1, 0, 1, 0, 1};
  Mesh mesh;
  mesh.n_spheres = 2;
  const Constriction k = throat_constriction(mesh, {0, 1, 2 + 2}, Packing{c, radius, walls});
  const double rho = (d * d + h * h - r * r) / (2 * (h + r));
  EXPECT_NEAR(k.radius, rho, 1e-14);
  EXPECT_NEAR(k.centre.y(), rho, 1e-14);
  EXPECT_NEAR(k.centre.x(), 0.5, 1e-14);
}

TEST(PowerCells, FillTheBoxAndMatchALattice) {
  const auto p = test::random_packing(300, 101);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const PowerCellVolumes v = power_cell_volumes(e.mesh(), e.cells(), Packing{p.centre, p.radius, p.walls});
  EXPECT_TRUE(v.incomplete.empty());
  EXPECT_NEAR(std::accumulate(v.volume.begin(), v.volume.end(), 0.0), 1.0, 1e-12);
  for (double x : v.volume) EXPECT_GT(x, 0);
  // Equal spheres on a perturbed cubic lattice of spacing 1/4: every power cell is a cell of the
  // lattice's Voronoi diagram up to the perturbation; the middle spheres' cells have volume 1/64.
  test::TestPacking q;
  q.walls.coord = {0, 1, 0, 1, 0, 1};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) {
        q.centre.emplace_back(0.125 + 0.25 * i, 0.125 + 0.25 * j + 1e-9 * k, 0.125 + 0.25 * k + 1e-9 * i);
        q.radius.push_back(0.1);
      }
  FlowEngine f = permeameter(0);
  f.step(q.centre, q.radius, q.walls, 1.0);
  const PowerCellVolumes w = power_cell_volumes(f.mesh(), f.cells(), Packing{q.centre, q.radius, q.walls});
  for (double x : w.volume) EXPECT_NEAR(x, 1.0 / 64, 1e-7);
}

TEST(CellGeometry, FindFacetAndHalfThroats) {
  const auto p = test::random_packing(250, 102);
  FlowEngine e = permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const Mesh& m = e.mesh();
  const FacetGeometry& g = e.facets();
  const Packing pk{p.centre, p.radius, p.walls};
  std::array<bool, kWallCount> solid{};
  solid.fill(true);
  int compared = 0;
  for (int c = 0; c < m.n_cells(); ++c)
    for (int l = 0; l < 4; ++l) {
      const int f = find_facet(g, m, c, l);
      ASSERT_GE(f, 0);
      const int n = m.cell_neighbours[c][l];
      EXPECT_TRUE((g.cell[f][0] == c && g.cell[f][1] == n) || (g.cell[f][0] == n && g.cell[f][1] == c));
      auto facet = g.vertex[f];
      std::sort(facet.begin(), facet.end());
      std::array<int, 3> expected{};
      for (int i = 0, k = 0; i < 4; ++i)
        if (i != l) expected[k++] = m.cell_vertices[c][i];
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(facet, expected);
      // Where both halves are proper (each centre on its own side), they add up to the throat's wetted area.
      if (n < 0 || c > n) continue;
      int ln = 0;
      while (m.cell_neighbours[n][ln] != c) ++ln;
      if (std::any_of(g.vertex[f].begin(), g.vertex[f].end(), [&](int x) { return m.is_wall(x); })) continue;
      const Vec3& x0 = p.centre[g.vertex[f][0]];
      const double height_a = -g.area_vector[f].dot(e.cells().power_centre[g.cell[f][0]] - x0);
      const double height_b = g.area_vector[f].dot(e.cells().power_centre[g.cell[f][1]] - x0);
      if (!(height_a > 0 && height_b > 0)) continue;
      const auto a = half_throat_wetted_area(m, e.cells(), pk, c, l, solid);
      const auto b = half_throat_wetted_area(m, e.cells(), pk, n, ln, solid);
      const double total = g.wetted_area[f][0] + g.wetted_area[f][1] + g.wetted_area[f][2];
      EXPECT_NEAR(a[0] + a[1] + a[2] + b[0] + b[1] + b[2], total, 1e-12 * total);
      ++compared;
    }
  EXPECT_GT(compared, 100);
}

TEST(CellVelocity, DarcyFluxTimesLengthAlongAPermeameter) {
  const auto p = test::random_packing(300, 103);
  FlowEngine e = permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const auto v = mean_cell_velocities(e.cells(), e.facets(), e.conductances(), e.pressure(), p.centre,
                                      static_cast<int>(p.centre.size()));
  // sum_c V_f v_c = sum_f q_f (P_b - P_a) = -sum_c P_c (flux out of c): only the Dirichlet cells
  // count; those of ymin lie on y = 0, those of ymax on y = 1, so along y it is Q (unit box).
  Vec3 sum = Vec3::Zero(), moment = Vec3::Zero();
  for (std::size_t c = 0; c < v.size(); ++c) {
    sum += e.cells().fluid_volume[c] * v[c];
    moment -= e.cells().power_centre[c] * cell_flux(e.system(), e.pressure(), e.volume_rates(), static_cast<int>(c));
  }
  const double q = boundary_flux(e, 3);
  EXPECT_NEAR(sum.y(), q, 1e-9 * q);
  EXPECT_LT((sum - moment).norm(), 1e-9 * q);
}

TEST(RemeshConditions, FlatCellsAreBlockedAtEachRemesh) {
  const auto p = test::random_packing(250, 104);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const double open = boundary_flux(e, 1);
  std::vector<double> v = e.cells().volume;
  std::nth_element(v.begin(), v.begin() + v.size() / 10, v.end());
  e.settings.flat_threshold = v[v.size() / 10];
  const int systems = e.system_builds();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.system_builds(), systems);  // applies from the next remesh
  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1.0);
  int blocked = 0;
  for (int c = 0; c < e.mesh().n_cells(); ++c) {
    EXPECT_EQ(e.cell_conditions().is_blocked(c), e.cells().volume[c] <= e.settings.flat_threshold);
    blocked += e.cell_conditions().is_blocked(c);
  }
  EXPECT_GT(blocked, 0);
  EXPECT_LT(boundary_flux(e, 1), open);
  EXPECT_NEAR(boundary_flux(e, 0) + boundary_flux(e, 1), 0, 1e-9 * open);
}

TEST(RemeshConditions, InterpolationCarriesBlockedCellsOver) {
  const auto p = test::random_packing(250, 105);
  for (const bool interpolate : {false, true}) {
    FlowEngine e = permeameter(0);
    e.settings.interpolate_on_remesh = interpolate;
    e.step(p.centre, p.radius, p.walls, 1.0);
    const Vec3 x(0.5, 0.5, 0.5);
    e.block_cell(locate(e, x), true);
    e.step(p.centre, p.radius, p.walls, 1.0);
    e.request_remesh();
    e.step(p.centre, p.radius, p.walls, 1.0);
    EXPECT_EQ(e.cell_conditions().is_blocked(locate(e, x)), interpolate);
    if (interpolate) {
      EXPECT_EQ(e.pressure()[locate(e, x)], 0.0);
    }
  }
}

TEST(RemeshConditions, MeshOnlyRemeshLeavesTheSystemToTheStep) {
  const auto p = test::random_packing(250, 106);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const double open = boundary_flux(e, 1);
  const int remeshes = e.remesh_count(), systems = e.system_builds();
  e.remesh(p.centre, p.radius, p.walls);
  EXPECT_EQ(e.remesh_count(), remeshes + 1);
  EXPECT_EQ(e.system_builds(), systems);
  e.block_cell(locate(e, Vec3(0.5, 0.5, 0.5)), false);  // what a blockHook does
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.remesh_count(), remeshes + 1);  // the step did not remesh again
  EXPECT_EQ(e.system_builds(), systems + 1);  // and built the system once, with the blocked cell
  EXPECT_LT(boundary_flux(e, 1), open);
}

TEST(PressureProfile, TheWallsCellsTakeThePressureAlongTheAxis) {
  const auto p = test::random_packing(250, 107);
  FlowEngine e;
  e.bc.is_pressure[2] = e.bc.is_pressure[3] = true;
  e.bc.value[3] = 5.0;
  e.bc.profile = {3, 0, {0.2, 0.8}, {0.0, 1.2}};
  validate(e.bc);
  e.step(p.centre, p.radius, p.walls, 1.0);
  int inside = 0, outside = 0;
  for (int c = 0; c < e.mesh().n_cells(); ++c) {
    if (!e.system().source[c].is_wall(3)) continue;
    const double x = e.cells().power_centre[c].x();
    if (x < 0.2 || x > 0.8) {
      EXPECT_EQ(e.pressure()[c], 5.0);
      ++outside;
    } else {
      EXPECT_NEAR(e.pressure()[c], 2.0 * (x - 0.2), 1e-12);
      ++inside;
    }
  }
  EXPECT_GT(inside, 0);
  EXPECT_GT(outside, 0);
  BoundaryConditions bad = e.bc;
  bad.profile.position = {0.5, 0.4};
  EXPECT_THROW(validate(bad), std::invalid_argument);
  bad.profile = {3, 1, {0.0, 1.0}, {0.0, 1.0}};  // along the wall's own axis
  EXPECT_THROW(validate(bad), std::invalid_argument);
}
