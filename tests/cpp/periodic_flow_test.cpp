// PeriodicFlow, the step of a periodic cell: undrained and drained loading, the identities of the
// model in the engine, and bad input refused before anything changes.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "periodic_packings.hpp"
#include "pfv/engine/periodic_flow.hpp"

using namespace pfv;
using pfv::test::diagonal;
using pfv::test::random_periodic;

namespace {

// The centres carried affinely from cell h0 to cell h1.
std::vector<Vec3> deformed(const std::vector<Vec3>& centres, const Eigen::Matrix3d& h0, const Eigen::Matrix3d& h1) {
  const Eigen::Matrix3d map = h1 * h0.inverse();
  std::vector<Vec3> out;
  for (const Vec3& x : centres) out.push_back(map * x);
  return out;
}

PeriodicFlowSettings settings(double bulk_modulus, const Vec3& gradient = Vec3::Zero()) {
  PeriodicFlowSettings s;
  s.bulk_modulus = bulk_modulus;
  s.viscosity = 1e-3;
  s.gradient = gradient;
  return s;
}

}  // namespace

TEST(PeriodicFlow, UndrainedLoadingRaisesThePressureByTheBulkModulus) {
  // A compressible fluid in a closed periodic cell: sum_c V_f,c dp_c = -K dV, whatever flows
  // between the pores. Isotropic compression with the spheres carried by the cell's velocity
  // gradient; a simple shear of the cell under spheres held in place (the cells that cross a
  // period are sheared through their images: volume moves between pores, none is lost); both.
  const auto p = random_periodic(100, 41, diagonal(1, 1.1, 0.9), 0.05, 0.08);
  const double dt = 1e-4, k = 2.0e6;
  for (int load = 0; load < 3; ++load) {
    PeriodicFlow flow;
    flow.set_settings(settings(k));
    flow.step(p.centre, p.radius, p.cell.h, dt);
    const std::vector<double> before = flow.periodic_pressure();
    Eigen::Matrix3d h1 = p.cell.h;
    if (load != 1) h1 *= 1.0 - 1e-4;  // isotropic compression
    if (load != 0) h1(0, 1) += 2e-4;  // the second vector leans along x
    flow.step(load == 1 ? p.centre : deformed(p.centre, p.cell.h, h1), p.radius, h1, dt);
    ASSERT_EQ(flow.remesh_count(), 1);
    const double dv = h1.determinant() - p.cell.h.determinant();
    double total_rate = 0, rise = 0, fluid = 0, spread = 0;
    for (double r : flow.volume_rates()) total_rate += r * dt;
    EXPECT_NEAR(total_rate, dv, 1e-12 * p.cell.volume()) << "load " << load;
    const auto& vf = flow.fluid_volumes();
    for (std::size_t c = 0; c < before.size(); ++c) {
      const double dp = flow.periodic_pressure()[c] - before[c];
      rise += vf[c] * dp;
      fluid += vf[c];
      spread = std::max(spread, std::abs(dp));
    }
    if (load == 1) {
      // Measured against the rise of the isotropic load (K times its volumetric strain 3e-4).
      EXPECT_NEAR(rise / fluid, 0.0, 1e-12 * k * 3e-4) << "the shear changes no volume";
      EXPECT_GT(spread, 1e6 * std::abs(rise / fluid)) << "but moves fluid between the pores";
    } else {
      const double expected = -k * dv / fluid;
      EXPECT_GT(expected, 0);
      EXPECT_NEAR(rise / fluid, expected, 1e-6 * expected) << "load " << load;
    }
  }
}

TEST(PeriodicFlow, DrainedSteadyFlowMatchesTheModelsIdentities) {
  // Incompressible, static spheres, an imposed gradient: the fluid force on the solid is
  // -gradP V, the flow goes down the gradient, and the pressure anywhere is p~ + gradP . x.
  Eigen::Matrix3d h = diagonal(1, 1, 1.2);
  h(1, 0) = 0.2;
  const auto p = random_periodic(90, 42, h, 0.05, 0.08);
  PeriodicFlow flow;
  const Vec3 gradient(0, -3.0, 1.0);
  flow.set_settings(settings(0, gradient));
  flow.step(p.centre, p.radius, p.cell.h, 1e-4);
  Vec3 total = Vec3::Zero();
  for (const Vec3& f : flow.forces()) total += f;
  const Vec3 expected = -gradient * p.cell.volume();
  EXPECT_LT((total - expected).norm(), 1e-8 * expected.norm());
  EXPECT_LT(flow.mean_velocity().dot(gradient), 0);
  // Static spheres: the second step changes nothing.
  const std::vector<double> first = flow.pressure();
  flow.step(p.centre, p.radius, p.cell.h, 1e-4);
  for (std::size_t c = 0; c < first.size(); ++c) EXPECT_NEAR(flow.pressure()[c], first[c], 1e-9);
  for (double r : flow.volume_rates()) EXPECT_EQ(r, 0.0);
  // A point inside a cell and its images in other periods: the pressure of the cell, p~ + gradP
  // at its power centre, and gradP . t more one translation t further.
  const auto& m = flow.mesh();
  const auto& v = m.mesh.cell_vertices[7];
  const Vec3 x = 0.25 * (m.image_centre[v[0]] + m.image_centre[v[1]] + m.image_centre[v[2]] + m.image_centre[v[3]]);
  const double px = flow.pressure()[7];
  EXPECT_NEAR(flow.pressure_at(x), px, 1e-12 * std::abs(px) + 1e-12);
  const Vec3 t = p.cell.translation({1, -2, 0});
  EXPECT_NEAR(flow.pressure_at(x + t), px + gradient.dot(t), 1e-9 * (std::abs(px) + 1));
  // A new gradient takes effect at the next step, on the same mesh and factor.
  const Vec3 other(1.5, 0, 0);
  flow.set_settings(settings(0, other));
  flow.step(p.centre, p.radius, p.cell.h, 1e-4);
  EXPECT_EQ(flow.remesh_count(), 1);
  PeriodicFlow fresh;
  fresh.set_settings(settings(0, other));
  fresh.step(p.centre, p.radius, p.cell.h, 1e-4);
  const Vec3 along_x = fresh.mean_velocity();
  EXPECT_LT((flow.mean_velocity() - along_x).norm(), 1e-9 * along_x.norm());
}

TEST(PeriodicFlow, ARemeshCarriesThePressuresAndKeepsDVdt) {
  // A remesh between two steps of a slow compression: dV/dt measured on the new cells from the
  // positions of the step before, so the undrained rise is the same as without the remesh.
  const auto p = random_periodic(80, 43, diagonal(1, 1, 1), 0.05, 0.08);
  const double dt = 1e-4, k = 1e6;
  std::vector<double> rise(2);
  for (int remesh = 0; remesh < 2; ++remesh) {
    PeriodicFlow flow;
    flow.set_settings(settings(k));
    flow.step(p.centre, p.radius, p.cell.h, dt);
    if (remesh) flow.request_remesh();
    const Eigen::Matrix3d h1 = p.cell.h * (1 - 1e-4);
    flow.step(deformed(p.centre, p.cell.h, h1), p.radius, h1, dt);
    EXPECT_EQ(flow.remesh_count(), 1 + remesh);
    double sum = 0, fluid = 0;
    for (std::size_t c = 0; c < flow.fluid_volumes().size(); ++c) {
      sum += flow.fluid_volumes()[c] * flow.periodic_pressure()[c];
      fluid += flow.fluid_volumes()[c];
    }
    rise[remesh] = sum / fluid;
  }
  // The fluid volumes of the two meshes differ a little (measured at different positions).
  EXPECT_NEAR(rise[1], rise[0], 1e-3 * rise[0]);
}

TEST(PeriodicFlow, RefusesBadInputAndChangesNothing) {
  const auto p = random_periodic(60, 44, diagonal(1, 1, 1), 0.05, 0.08);
  PeriodicFlow flow;
  EXPECT_THROW(flow.set_settings(settings(0, Vec3(NAN, 0, 0))), std::invalid_argument);
  EXPECT_THROW(flow.set_settings(settings(-1)), std::invalid_argument);
  PeriodicFlowSettings bad = settings(0);
  bad.viscosity = 0;
  EXPECT_THROW(flow.set_settings(bad), std::invalid_argument);
  // Thinner than two diameters of the largest sphere (0.16) along z.
  EXPECT_THROW(flow.step(p.centre, p.radius, diagonal(1, 1, 0.3), 1e-4), std::invalid_argument);
  EXPECT_FALSE(flow.has_mesh());
  EXPECT_THROW(flow.step(p.centre, p.radius, p.cell.h, 0.0), std::invalid_argument);
  Eigen::Matrix3d left = p.cell.h;
  left.col(2) *= -1;
  EXPECT_THROW(flow.step(p.centre, p.radius, left, 1e-4), std::invalid_argument);
  flow.step(p.centre, p.radius, p.cell.h, 1e-4);
  const std::vector<double> kept = flow.periodic_pressure();
  auto nan_centre = p.centre;
  nan_centre[3] = Vec3(0, NAN, 0);
  EXPECT_THROW(flow.step(nan_centre, p.radius, p.cell.h, 1e-4), std::invalid_argument);
  auto bad_radius = p.radius;
  bad_radius[5] = -0.1;
  flow.request_remesh();
  EXPECT_THROW(flow.step(p.centre, bad_radius, p.cell.h, 1e-4), std::invalid_argument);
  EXPECT_EQ(flow.remesh_count(), 1);
  EXPECT_EQ(flow.periodic_pressure(), kept);
}

TEST(PeriodicFlow, DefToleranceRemeshesOnceThePoresHaveStrainedEnough) {
  // The cell and its spheres shrink by 1e-4 per step: every pore's volume by 1 - (1 - 1e-4)^3 =
  // 3.0e-4 per step. With YADE's defTolerance 1e-3 the strain passes it on the fourth step after
  // the mesh, and the fifth remeshes; without it the mesh stays.
  const auto p = random_periodic(80, 43, diagonal(1, 1, 1), 0.05, 0.08);
  for (const double tolerance : {1e-3, 0.0}) {
    PeriodicFlowSettings s = settings(0.0);
    s.def_tolerance = tolerance;
    PeriodicFlow flow;
    flow.set_settings(s);
    Eigen::Matrix3d h = p.cell.h;
    flow.step(p.centre, p.radius, h, 1e-4);
    for (int step = 1; step <= 5; ++step) {
      const Eigen::Matrix3d next = h * (1 - 1e-4);
      const auto x = deformed(p.centre, p.cell.h, next);
      h = next;
      flow.step(x, p.radius, h, 1e-4);
      const int expected = tolerance > 0 && step == 5 ? 2 : 1;
      EXPECT_EQ(flow.remesh_count(), expected) << "tolerance " << tolerance << ", step " << step;
      // each step dV / V = (1 - 1e-4)^-3 - 1, V the step's new volume
      if (step == 4) {
        EXPECT_NEAR(flow.strain(), 4 * (std::pow(1 - 1e-4, -3) - 1), 1e-9);
      }
    }
  }
}

TEST(PeriodicFlow, RemeshesKeepTheUndrainedPressureOfACompressibleFluid) {
  // Undrained compression with a remesh at every step: within a mesh the storage makes
  // sum_c V_f,c dp~_c = -K dV exactly, and a remesh carries the V_f-weighted mean p~ over, so after
  // n steps the mean is sum_k -K dV_k / V_f,k, V_f,k the fluid volume of step k's mesh. (Carried
  // by position alone the mean drifted by 1.4e-5 of the rise here.)
  const auto p = random_periodic(90, 45, diagonal(1, 1.1, 0.9), 0.05, 0.08);
  const double dt = 1e-4, k = 1e6;
  PeriodicFlow flow;
  flow.set_settings(settings(k, Vec3(0, 30, 0)));
  flow.step(p.centre, p.radius, p.cell.h, dt);
  const auto mean = [&] {
    double sum = 0, fluid = 0;
    for (std::size_t c = 0; c < flow.fluid_volumes().size(); ++c) {
      sum += flow.fluid_volumes()[c] * flow.periodic_pressure()[c];
      fluid += flow.fluid_volumes()[c];
    }
    return std::make_pair(sum / fluid, fluid);
  };
  double expected = mean().first;
  Eigen::Matrix3d h = p.cell.h;
  for (int step = 1; step <= 10; ++step) {
    Eigen::Matrix3d next = h * (1 - 2e-4);
    next(0, 1) += 1e-4;  // and a shear
    flow.request_remesh();
    flow.step(deformed(p.centre, p.cell.h, next), p.radius, next, dt);
    expected += -k * (next.determinant() - h.determinant()) / mean().second;
    h = next;
  }
  EXPECT_EQ(flow.remesh_count(), 11);
  EXPECT_NEAR(mean().first, expected, 1e-9 * std::abs(expected));
}
