// The optional viscous shear force (thesis 6.29-6.30): dual-facet areas against exact
// geometry, invariances, momentum, linearity, a hand computation, and zero cost when off.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/model/force_cache.hpp"
#include "pfv/model/viscous_shear.hpp"
#include "test_packings.hpp"

using namespace pfv;
using test::permeameter;

namespace {

// m^3 equal spheres on a simple cubic lattice of spacing a = 1/m filling the unit box, so that
// every power cell, walls included, is a cube of side a.
test::TestPacking cubic_lattice(int m, double radius_fraction) {
  test::TestPacking p;
  p.walls.coord = {0, 1, 0, 1, 0, 1};
  const double a = 1.0 / m;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k) p.centre.emplace_back((i + 0.5) * a, (j + 0.5) * a, (k + 0.5) * a);
  p.radius.assign(p.centre.size(), radius_fraction * a / 2);
  return p;
}

FlowEngine shear_engine(bool slip = true, double mu = 1.0) {
  FlowEngine e = permeameter(1, 0.0);
  e.settings.viscous_shear = true;
  e.settings.slip_boundary = slip;
  e.settings.conductance.viscosity = mu;
  return e;
}

// Positions after dt under a velocity field.
template <class Field>
std::vector<Vec3> moved(const std::vector<Vec3>& x, double dt, const Field& v) {
  std::vector<Vec3> y(x);
  for (std::size_t k = 0; k < x.size(); ++k) y[k] = x[k] + dt * v(x[k], static_cast<int>(k));
  return y;
}

double norm_sum(const std::vector<Vec3>& f) {
  double s = 0;
  for (const Vec3& x : f) s += x.norm();
  return s;
}

}  // namespace

TEST(ViscousShear, CubicLatticeFacetsAreSquaresOfSideA) {
  // Cospherical groups: the triangulation has diagonal edges too, whose dual facets have zero
  // area and must not be kept; every nearest-neighbour pair has S_vor = a^2 (walls included).
  const int m = 5;
  const double a = 1.0 / m;
  const auto p = cubic_lattice(m, 0.9);
  FlowEngine e = shear_engine();
  e.step(p.centre, p.radius, p.walls, 1.0);
  const ViscousShear* s = e.viscous_shear();
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->open_rings, 0);
  EXPECT_EQ(s->size(), 3 * m * m * (m - 1));
  for (int k = 0; k < s->size(); ++k) {
    ASSERT_LT(s->b[k], e.mesh().n_spheres);  // slip walls: sphere pairs only
    EXPECT_NEAR((p.centre[s->b[k]] - p.centre[s->a[k]]).norm(), a, 1e-12);
    EXPECT_NEAR(s->area[k], a * a, 1e-12 * a * a);
    EXPECT_GT(s->hydraulic_radius[k], 0);
  }
}

TEST(ViscousShear, PowerCellsTileTheBox) {
  // Sum over pairs of S_vor * d / 3 (the two pyramids on the facet, apexes at both centres; power
  // distances add up to d) plus S_vor * h / 3 for the wall faces = the box volume, exactly, for
  // any polydisperse packing. With no-slip walls the sphere-wall pairs are kept, so all faces are.
  for (unsigned seed : {31u, 32u}) {
    const auto p = test::random_packing(300, seed, 0.02, 0.06);
    FlowEngine e = shear_engine(false);
    e.step(p.centre, p.radius, p.walls, 1.0);
    const ViscousShear& s = *e.viscous_shear();
    EXPECT_EQ(s.open_rings, 0);
    const int n = e.mesh().n_spheres;
    double volume = 0;
    int walls = 0;
    for (int k = 0; k < s.size(); ++k) {
      const Vec3& x = p.centre[s.a[k]];
      if (s.b[k] >= n) {
        ++walls;
        volume += s.area[k] * p.walls.height(s.b[k] - n, x) / 3;
      } else {
        volume += s.area[k] * (p.centre[s.b[k]] - x).norm() / 3;
      }
    }
    EXPECT_GT(walls, 0);
    EXPECT_NEAR(volume, 1.0, 1e-12);
  }
}

TEST(ViscousShear, RigidTranslationGivesNoShear) {
  const auto p = test::random_packing(300, 33);
  FlowEngine e = shear_engine();
  const double dt = 1e-3;
  e.step(p.centre, p.radius, p.walls, dt);
  const Vec3 u(0.3, -0.2, 0.5);
  e.step(moved(p.centre, dt, [&](const Vec3&, int) { return u; }), p.radius, p.walls, dt);
  ASSERT_EQ(e.shear_forces().size(), p.centre.size() + 6);
  // Scale: the same speed as a shear field.
  FlowEngine ref = shear_engine();
  ref.step(p.centre, p.radius, p.walls, dt);
  ref.step(moved(p.centre, dt, [&](const Vec3& x, int) { return Vec3(u.norm() * (x.y() - 0.5), 0, 0); }), p.radius,
           p.walls, dt);
  const double scale = norm_sum(ref.shear_forces());
  EXPECT_GT(scale, 0);
  // Positions differ by rounding only: (x + u dt) - x is u dt to 1e-13 relative.
  EXPECT_LT(norm_sum(e.shear_forces()), 1e-10 * scale);
}

TEST(ViscousShear, ForcesSumToZero) {
  // Every pair acts with +F and -F, walls included (no-slip).
  const auto p = test::random_packing(300, 34);
  FlowEngine e = shear_engine(false);
  const double dt = 1e-3;
  e.step(p.centre, p.radius, p.walls, dt);
  std::mt19937 gen(7);
  std::normal_distribution<double> g;
  e.step(moved(p.centre, dt, [&](const Vec3&, int) { return Vec3(g(gen), g(gen), g(gen)); }), p.radius, p.walls, dt);
  Vec3 total = Vec3::Zero(), on_walls = Vec3::Zero();
  for (std::size_t v = 0; v < e.shear_forces().size(); ++v) {
    total += e.shear_forces()[v];
    if (v >= p.centre.size()) on_walls += e.shear_forces()[v];
  }
  const double scale = norm_sum(e.shear_forces());
  EXPECT_GT(on_walls.norm(), 1e-3 * scale / p.centre.size());  // the walls do take their part
  EXPECT_LT(total.norm(), 1e-13 * scale);
}

TEST(ViscousShear, LinearInViscosityAndVelocity) {
  const auto p = test::random_packing(200, 35);
  std::mt19937 gen(8);
  std::normal_distribution<double> g;
  std::vector<Vec3> u(p.centre.size());
  for (Vec3& x : u) x = Vec3(g(gen), g(gen), g(gen));
  const double dt = 1e-3;
  const auto x1 = moved(p.centre, dt, [&](const Vec3&, int k) { return u[k]; });
  auto run = [&](double mu, double step) {
    FlowEngine e = shear_engine(true, mu);
    e.step(p.centre, p.radius, p.walls, step);
    e.step(x1, p.radius, p.walls, step);  // same displacement: velocity dt / step times u
    return e.shear_forces();
  };
  const auto base = run(1.0, dt), mu = run(2.5, dt), fast = run(1.0, dt / 3);
  const double scale = norm_sum(base) / base.size();
  ASSERT_GT(scale, 0);
  for (std::size_t v = 0; v < base.size(); ++v) {
    EXPECT_LT((mu[v] - 2.5 * base[v]).norm(), 1e-12 * scale);
    EXPECT_LT((fast[v] - 3.0 * base[v]).norm(), 1e-12 * scale);
  }
}

TEST(ViscousShear, SimpleShearOfTwoSpheresByHand) {
  // Two spheres one above the other in the unit box; v = gamma_dot * y * e_x. Their power
  // facet is the plane y = 0.5 clipped by the box: S_vor = 1. R_h is the hydraulic radius of
  // the throats around the pair, phi / gamma summed over them, read here from the throat
  // geometry independently of the ring walk. F_0 = +mu S / R_h * gamma_dot * 0.4 e_x: the
  // lower, slower sphere is dragged forward, the upper one held back.
  test::TestPacking p;
  p.walls.coord = {0, 1, 0, 1, 0, 1};
  p.centre = {Vec3(0.5, 0.3, 0.5), Vec3(0.5, 0.7, 0.5)};
  p.radius = {0.15, 0.15};
  const double mu = 0.7, gamma_dot = 2.0, dt = 1e-4;
  FlowEngine e = shear_engine(true, mu);
  e.step(p.centre, p.radius, p.walls, dt);
  e.step(moved(p.centre, dt, [&](const Vec3& x, int) { return Vec3(gamma_dot * x.y(), 0, 0); }), p.radius, p.walls, dt);

  const ViscousShear& s = *e.viscous_shear();
  ASSERT_EQ(s.size(), 1);
  EXPECT_NEAR(s.area[0], 1.0, 1e-12);
  double phi = 0, gamma = 0;
  int throats = 0;
  const FacetGeometry& f = e.facets();
  for (int t = 0; t < f.size(); ++t) {
    const auto& v = f.vertex[t];
    const bool has0 = v[0] == 0 || v[1] == 0 || v[2] == 0, has1 = v[0] == 1 || v[1] == 1 || v[2] == 1;
    if (!has0 || !has1) continue;
    ++throats;
    const double g = f.wetted_area[t][0] + f.wetted_area[t][1] + f.wetted_area[t][2];
    phi += f.hydraulic_radius[t] * g;
    gamma += g;
  }
  EXPECT_EQ(throats, 4);  // one per lateral wall
  const double rh = phi / gamma;
  EXPECT_NEAR(s.hydraulic_radius[0], rh, 1e-14);
  const double fx = mu * 1.0 / rh * gamma_dot * 0.4;
  const auto& F = e.shear_forces();
  EXPECT_GT(F[0].x(), 0);
  EXPECT_NEAR(F[0].x(), fx, 1e-9 * fx);
  EXPECT_NEAR(F[1].x(), -fx, 1e-9 * fx);
  EXPECT_NEAR(F[0].y(), 0, 1e-12 * fx);
  EXPECT_NEAR(F[0].z(), 0, 1e-12 * fx);
  for (int w = 0; w < 6; ++w) EXPECT_EQ(F[2 + w].norm(), 0.0);  // slip walls take no shear
  // forces() carries it: the difference to the shear-free engine is the shear force.
  FlowEngine off = permeameter(1, 0.0);
  off.settings.conductance.viscosity = mu;
  off.step(p.centre, p.radius, p.walls, dt);
  off.step(moved(p.centre, dt, [&](const Vec3& x, int) { return Vec3(gamma_dot * x.y(), 0, 0); }), p.radius, p.walls,
           dt);
  EXPECT_NEAR(e.forces()[0].x() - off.forces()[0].x(), fx, 1e-9 * fx);
}

TEST(ViscousShear, SimpleShearOfALatticeOpposesTheRelativeMotion) {
  // Under v = gamma_dot y e_x the lower half is dragged forward, the upper half held back,
  // by equal and opposite amounts.
  const auto p = cubic_lattice(4, 0.9);
  FlowEngine e = shear_engine();
  const double dt = 1e-3;
  e.step(p.centre, p.radius, p.walls, dt);
  e.step(moved(p.centre, dt, [](const Vec3& x, int) { return Vec3(x.y(), 0, 0); }), p.radius, p.walls, dt);
  double lower = 0, upper = 0;
  for (std::size_t k = 0; k < p.centre.size(); ++k) (p.centre[k].y() < 0.5 ? lower : upper) += e.shear_forces()[k].x();
  EXPECT_GT(lower, 0);
  EXPECT_NEAR(upper, -lower, 1e-12 * lower);
}

TEST(ViscousShear, OffLeavesTheForcesBitIdentical) {
  const auto p = test::random_packing(300, 36);
  const double dt = 1e-3;
  std::mt19937 gen(9);
  std::normal_distribution<double> g;
  const auto x1 = moved(p.centre, dt, [&](const Vec3&, int) { return Vec3(g(gen), g(gen), g(gen)); });
  FlowEngine off = permeameter(1);
  off.step(p.centre, p.radius, p.walls, dt);
  off.step(x1, p.radius, p.walls, dt);
  EXPECT_EQ(off.viscous_shear(), nullptr);  // nothing built or stored
  EXPECT_TRUE(off.shear_forces().empty());
  EXPECT_EQ(off.remesh_times().shear_geometry, 0.0);
  EXPECT_EQ(off.step_times().shear_forces, 0.0);
  // Its forces are exactly the pressure-and-drag map F = S p, rebuilt here from the mesh.
  ForceCache cache;
  cache.build(off.mesh(), off.facets(), Packing{p.centre, p.radius, p.walls});
  std::vector<Vec3> reference;
  cache.apply(off.pressure(), reference);
  ASSERT_EQ(reference.size(), off.forces().size());
  for (std::size_t v = 0; v < reference.size(); ++v)
    for (int a = 0; a < 3; ++a) EXPECT_EQ(off.forces()[v][a], reference[v][a]);
  // On, with the spheres at rest, adds exact zeros.
  FlowEngine on = permeameter(1);
  on.settings.viscous_shear = true;
  on.step(p.centre, p.radius, p.walls, dt);
  on.step(p.centre, p.radius, p.walls, dt);
  FlowEngine rest = permeameter(1);
  rest.step(p.centre, p.radius, p.walls, dt);
  rest.step(p.centre, p.radius, p.walls, dt);
  for (std::size_t v = 0; v < reference.size(); ++v)
    for (int a = 0; a < 3; ++a) EXPECT_EQ(on.forces()[v][a], rest.forces()[v][a]);
}

TEST(ViscousShear, SwitchingOnRemeshesAndOffFreesThePairs) {
  const auto p = test::random_packing(100, 37);
  FlowEngine e = permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.remesh_count(), 1);
  e.settings.viscous_shear = true;
  EXPECT_TRUE(e.remesh_due());
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.remesh_count(), 2);
  ASSERT_NE(e.viscous_shear(), nullptr);
  EXPECT_EQ(e.shear_forces().size(), p.centre.size() + 6);
  e.settings.viscous_shear = false;
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.remesh_count(), 2);
  EXPECT_EQ(e.viscous_shear(), nullptr);
  EXPECT_TRUE(e.shear_forces().empty());
}

TEST(ViscousShear, NonFiniteShearIsRefusedAndTheEngineUnchanged) {
  // Two spheres, every cell touching a pressure wall: no unknown pressure, so the shear is
  // the only force that can overflow.
  test::TestPacking p;
  p.walls.coord = {0, 1, 0, 1, 0, 1};
  p.centre = {Vec3(0.5, 0.3, 0.5), Vec3(0.5, 0.7, 0.5)};
  p.radius = {0.15, 0.15};
  FlowEngine e = shear_engine(true, 1e300);
  e.bc.is_pressure.fill(true);
  e.step(p.centre, p.radius, p.walls, 1.0);
  std::vector<Vec3> x1 = p.centre;
  x1[0].x() += 1e-3;
  e.step(x1, p.radius, p.walls, 1.0);
  ASSERT_EQ(e.system().n_unknowns(), 0);
  const auto forces = e.forces(), shear = e.shear_forces();
  const auto pressure = e.pressure();
  ASSERT_TRUE(shear[0].allFinite());
  std::vector<Vec3> x2 = x1;
  x2[0].x() += 1e-2;
  EXPECT_THROW(e.step(x2, p.radius, p.walls, 1e-20), std::domain_error);
  EXPECT_EQ(e.forces(), forces);
  EXPECT_EQ(e.shear_forces(), shear);
  EXPECT_EQ(e.pressure(), pressure);
  // The engine carries on from the last good step.
  e.step(x2, p.radius, p.walls, 1.0);
  EXPECT_TRUE(e.shear_forces()[0].allFinite());
}

TEST(ViscousShear, ShearViscosityScalesTheShearTermOnly) {
  const auto p = test::random_packing(300, 41);
  const double dt = 1e-3;
  std::mt19937 gen(5);
  std::normal_distribution<double> g;
  const auto x1 = moved(p.centre, dt, [&](const Vec3&, int) { return Vec3(g(gen), g(gen), g(gen)); });
  FlowEngine same = shear_engine(), quarter = shear_engine();
  quarter.settings.shear_viscosity = 0.25 * quarter.settings.conductance.viscosity;
  for (FlowEngine* e : {&same, &quarter}) {
    e->step(p.centre, p.radius, p.walls, dt);
    e->step(x1, p.radius, p.walls, dt);
  }
  ASSERT_FALSE(same.shear_forces().empty());
  ASSERT_GT(norm_sum(same.shear_forces()), 0);
  for (std::size_t v = 0; v < same.shear_forces().size(); ++v)
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(quarter.shear_forces()[v][a], 0.25 * same.shear_forces()[v][a],
                  1e-12 * std::abs(same.shear_forces()[v][a]) + 1e-300);
      // The pressure and drag part F - F_shear is the same in both.
      const double rest = same.forces()[v][a] - same.shear_forces()[v][a];
      EXPECT_NEAR(quarter.forces()[v][a] - quarter.shear_forces()[v][a], rest, 1e-12 * (std::abs(rest) + 1));
    }
  quarter.settings.shear_viscosity = -1;
  EXPECT_THROW(quarter.step(x1, p.radius, p.walls, dt), std::invalid_argument);
}
