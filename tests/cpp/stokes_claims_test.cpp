// The claims of the thesis' comparison with Stokes flow (section 3.5.4) that need no FEM:
// the total fluid force on the solid phase is dP S, and on the 8-sphere cubic packing every
// sphere takes S dP / 8. Also the split of the forces into pressure and viscous parts, and the
// YADE wall-throat factor, PFV's default (doc/validation.md section 7).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "pfv/model/force_parts.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

constexpr int kYmin = 2, kYmax = 3;

// Eight spheres of radius 1/4 in the unit cube, touching each other and the walls.
test::TestPacking cubic8() {
  test::TestPacking p;
  for (double x : {0.25, 0.75})
    for (double y : {0.25, 0.75})
      for (double z : {0.25, 0.75}) {
        p.centre.emplace_back(x, y, z);
        p.radius.push_back(0.25);
      }
  p.walls.coord = {0, 1, 0, 1, 0, 1};
  return p;
}

// The cubic 8 and a centre sphere of diameter ratio d/D, every radius shrunk by 1 % (the FEM
// comparison's packing, validation/stokes/packings.py).
test::TestPacking centred9(double d_over_D) {
  test::TestPacking p = cubic8();
  p.centre.emplace_back(0.5, 0.5, 0.5);
  p.radius.push_back(0.25 * d_over_D);
  for (double& r : p.radius) r *= 0.99;
  return p;
}

// y component of the fluid force on the solid phase: the spheres and the four lateral walls.
double solid_force_y(const FlowEngine& e, int n_spheres) {
  double f = 0;
  for (int v = 0; v < n_spheres + kWallCount; ++v)
    if (v != n_spheres + kYmin && v != n_spheres + kYmax) f += e.forces()[v].y();
  return f;
}

FlowEngine permeameter_y(bool slip) {
  FlowEngine e = test::permeameter(1, 1.0);
  e.settings.slip_boundary = slip;
  return e;
}

}  // namespace

TEST(StokesClaims, TotalForceOnTheSolidIsDpTimesSection) {
  const auto cubic = cubic8();
  const auto random = test::random_packing(300, 17);
  for (const auto* p : {&cubic, &random})
    for (bool slip : {true, false}) {
      FlowEngine e = permeameter_y(slip);
      e.step(p->centre, p->radius, p->walls, 1.0);
      const int n = static_cast<int>(p->radius.size());
      const double section = (p->walls.coord[1] - p->walls.coord[0]) * (p->walls.coord[5] - p->walls.coord[4]);
      EXPECT_NEAR(solid_force_y(e, n), 1.0 * section, 1e-7 * section) << n << " spheres, slip " << slip;
    }
}

TEST(StokesClaims, EverySphereOfTheCubicPackingTakesAnEighth) {
  // The cubic packing is cospherical: its cavities are split into cells with coincident power
  // centres (L = 0), which only the clamp connects. With the clamp's upper bound far above the
  // other throats those cells act as one pore and the packing's symmetry is restored.
  const auto p = cubic8();
  FlowEngine e = permeameter_y(true);
  e.settings.conductance.max_ratio = 1e10;
  e.step(p.centre, p.radius, p.walls, 1.0);
  for (int s = 0; s < 8; ++s) EXPECT_NEAR(e.forces()[s].y(), 1.0 / 8, 1e-6) << "sphere " << s;
  // No-slip walls take a viscous share; the spheres still share the rest equally.
  FlowEngine ns = permeameter_y(false);
  ns.settings.conductance.max_ratio = 1e10;
  ns.step(p.centre, p.radius, p.walls, 1.0);
  const double each = ns.forces()[0].y();
  EXPECT_LT(each, 1.0 / 8 - 1e-3);
  for (int s = 1; s < 8; ++s) EXPECT_NEAR(ns.forces()[s].y(), each, 1e-6) << "sphere " << s;
}

TEST(StokesClaims, PressureAndViscousPartsAddUpToTheForce) {
  const auto p = test::random_packing(200, 23);
  for (bool slip : {true, false}) {
    FlowEngine e = permeameter_y(slip);
    e.step(p.centre, p.radius, p.walls, 1.0);
    const ForceParts parts =
        split_fluid_forces(e.mesh(), e.facets(), Packing{p.centre, p.radius, p.walls}, e.pressure());
    double viscous_walls = 0;
    for (std::size_t v = 0; v < e.forces().size(); ++v) {
      EXPECT_LT((parts.pressure[v] + parts.viscous[v] - e.forces()[v]).norm(), 1e-12) << "vertex " << v;
      if (v >= p.radius.size()) viscous_walls += parts.viscous[v].norm();
    }
    if (slip)
      EXPECT_EQ(viscous_walls, 0.0);  // slip walls take no viscous force
    else
      EXPECT_GT(viscous_walls, 0.0);
  }
}

TEST(StokesClaims, YadeWallThroatFactorScalesOnlyWallThroats) {
  // Without the clamp, whose reference (the median k) the factor moves.
  const auto p = test::random_packing(200, 29);
  FlowEngine plain = permeameter_y(true);
  plain.settings.conductance.clamp = false;
  plain.settings.yade_wall_throat_factor = false;  // the thesis' formula alone
  plain.step(p.centre, p.radius, p.walls, 1.0);
  FlowEngine yade = permeameter_y(true);
  yade.settings.conductance.clamp = false;
  yade.settings.yade_wall_throat_factor = true;
  yade.step(p.centre, p.radius, p.walls, 1.0);
  ASSERT_EQ(plain.conductances().size(), yade.conductances().size());
  int one = 0, two = 0;
  for (int f = 0; f < plain.facets().size(); ++f) {
    int walls = 0;
    for (int v : plain.facets().vertex[f]) walls += plain.mesh().is_wall(v) ? 1 : 0;
    const double k0 = plain.conductances()[f], k1 = yade.conductances()[f];
    const double expected = walls == 0 ? 1.0 : walls == 1 ? std::sqrt(0.5) : 0.5;  // (R_h factor)^2
    if (k0 > 0) {
      EXPECT_NEAR(k1 / k0, expected, 1e-12) << "facet " << f << ", " << walls << " wall vertices";
    }
    one += walls == 1 && k0 > 0;
    two += walls == 2 && k0 > 0;
  }
  EXPECT_GT(one, 0);
  EXPECT_GT(two, 0);
  EXPECT_LT(boundary_flux(yade, kYmax), 0.95 * boundary_flux(plain, kYmax));
  // The geometric R_h is kept for everything else.
  EXPECT_EQ(plain.facets().hydraulic_radius, yade.facets().hydraulic_radius);
  // No effect with no-slip walls.
  FlowEngine ns = permeameter_y(false), ns_yade = permeameter_y(false);
  ns.settings.yade_wall_throat_factor = false;
  ns_yade.settings.yade_wall_throat_factor = true;
  ns.step(p.centre, p.radius, p.walls, 1.0);
  ns_yade.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(ns.conductances(), ns_yade.conductances());
}

TEST(StokesClaims, APoreCutByAnArbitraryFacetStaysOnePore) {
  // In the 9-sphere packing every cavity face is a square of cospherical spheres, and the two
  // cells on either side of its diagonal share their power centre, which floating point returns
  // equal or a few ulps apart depending on the radii. Either way the throat between them has
  // length 0 and takes the clamp's upper bound; taken as a throat of round-off length and
  // round-off hydraulic radius it was closed instead, which cut the pores in two: the centre
  // sphere then took a lateral force as large as its force along the flow, and the
  // permeability moved by 7.6 % when the centres were moved by 1e-6.
  const auto exact = centred9(0.1);
  auto moved = exact;
  std::mt19937 gen(1);
  std::uniform_real_distribution<double> u(-1e-6, 1e-6);
  for (Vec3& x : moved.centre) x += Vec3(u(gen), u(gen), u(gen));
  double flux[2];
  for (int k = 0; k < 2; ++k) {
    const auto& p = k == 0 ? exact : moved;
    FlowEngine e = permeameter_y(false);
    e.settings.conductance.max_ratio = 1e10;
    e.step(p.centre, p.radius, p.walls, 1.0);
    flux[k] = boundary_flux(e, kYmax);
    const Vec3 f = e.forces()[8];
    EXPECT_GT(f.y(), 0);
    EXPECT_LT(std::hypot(f.x(), f.z()), 1e-3 * f.y()) << (k == 0 ? "exact" : "moved") << " centres";
  }
  EXPECT_NEAR(flux[0] / flux[1], 1.0, 0.02);
}
