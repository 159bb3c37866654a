// PeriodicFlow's point conditions (imposed pressures and fluxes) and its run state (a run saved
// and resumed goes on as if uninterrupted).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "periodic_packings.hpp"
#include "pfv/engine/periodic_flow.hpp"

using namespace pfv;
using pfv::test::diagonal;
using pfv::test::random_periodic;

namespace {

PeriodicFlowSettings settings(const Vec3& gradient, double bulk_modulus = 0.0) {
  PeriodicFlowSettings s;
  s.viscosity = 1e-3;
  s.gradient = gradient;
  s.bulk_modulus = bulk_modulus;
  return s;
}

double largest_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

double largest(const std::vector<double>& a) {
  double d = 0;
  for (double x : a) d = std::max(d, std::abs(x));
  return d;
}

}  // namespace

TEST(PeriodicConditions, AnImposedPressureShiftsTheSolutionByAConstant) {
  // Static spheres, incompressible: the flow under gradP alone fixes p~ up to a constant, so an
  // imposed pressure (in place of the reference pore) changes every pore's pressure by the same
  // amount, and the pressure at the imposed point is the imposed value, in any period.
  Eigen::Matrix3d h = diagonal(1, 1.1, 0.9);
  h(0, 2) = 0.15;
  const auto p = random_periodic(80, 51, h, 0.05, 0.08);
  const Vec3 gradient(0.3, -1.0, 0.5);
  PeriodicFlow free, fixed;
  free.set_settings(settings(gradient));
  fixed.set_settings(settings(gradient));
  const Vec3 point = h * Vec3(1.37, -0.62, 2.21);  // outside the base cell
  EXPECT_EQ(fixed.impose_pressure(point, 250.0), 0);
  free.step(p.centre, p.radius, h, 1e-4);
  fixed.step(p.centre, p.radius, h, 1e-4);
  EXPECT_NEAR(fixed.pressure_at(point), 250.0, 1e-9);
  const std::vector<double> a = free.pressure(), b = fixed.pressure();
  const double shift = b[0] - a[0];
  std::vector<double> shifted(a.size());
  for (std::size_t c = 0; c < a.size(); ++c) shifted[c] = a[c] + shift;
  const double scale = largest(free.periodic_pressure());
  ASSERT_GT(scale, 0);
  EXPECT_LT(largest_difference(shifted, b), 1e-9 * scale);
  for (std::size_t s = 0; s < p.centre.size(); ++s)
    EXPECT_LT((free.forces()[s] - fixed.forces()[s]).norm(), 1e-9 * scale) << "a constant pressure exerts no force";
  // A new value holds at the next step without a new system; the shift follows it.
  fixed.set_imposed_pressure(0, -40.0);
  fixed.step(p.centre, p.radius, h, 1e-4);
  EXPECT_NEAR(fixed.pressure_at(point), -40.0, 1e-9);
  EXPECT_NEAR(fixed.pressure()[0] - b[0], -290.0, 1e-9);
  EXPECT_THROW(fixed.set_imposed_pressure(1, 0.0), std::out_of_range);
  EXPECT_THROW(fixed.impose_pressure(Vec3(NAN, 0, 0), 1.0), std::invalid_argument);
  EXPECT_THROW(fixed.impose_pressure(point, INFINITY), std::invalid_argument);
  EXPECT_EQ(fixed.imposed_pressures().size(), 1u);
}

TEST(PeriodicConditions, AnImposedFluxFlowsToTheImposedPressure) {
  // No gradient, static spheres: an inflow Q at one point and a pressure at another. The
  // pressure rises where the fluid enters, in proportion to Q, and the response is reciprocal
  // (the pressure at C of an inflow at B equals that at B of the same inflow at C: G is
  // symmetric). Without an imposed pressure the reference pore (that of cell 0) takes the
  // inflow: the same as a pressure imposed in it.
  const auto p = random_periodic(70, 52, diagonal(1, 1, 1), 0.05, 0.08);
  const Vec3 a(0.11, 0.13, 0.17), b(0.52, 0.61, 0.43), c(0.83, 0.27, 0.71);
  const auto response = [&](const Vec3& in, double q, const Vec3& probe) {
    PeriodicFlow flow;
    flow.set_settings(settings(Vec3::Zero()));
    flow.impose_pressure(a, 0.0);
    flow.impose_flux(in, q);
    flow.step(p.centre, p.radius, p.cell.h, 1e-4);
    return flow.pressure_at(probe) - flow.pressure_at(a);
  };
  const double at_b = response(b, 2e-6, b);
  EXPECT_GT(at_b, 0) << "the pressure rises where the fluid is pushed in";
  EXPECT_NEAR(response(b, 4e-6, b), 2 * at_b, 1e-9 * at_b);
  const double cb = response(b, 2e-6, c), bc = response(c, 2e-6, b);
  EXPECT_NEAR(cb, bc, 1e-9 * at_b);

  PeriodicFlow reference;
  reference.set_settings(settings(Vec3::Zero()));
  reference.impose_flux(b, 2e-6);
  reference.step(p.centre, p.radius, p.cell.h, 1e-4);
  const PeriodicMesh& m = reference.mesh();
  Vec3 centroid = Vec3::Zero();
  for (int v : m.mesh.cell_vertices[0]) centroid += m.image_centre[v] / 4;
  PeriodicFlow imposed;
  imposed.set_settings(settings(Vec3::Zero()));
  imposed.impose_pressure(centroid, 0.0);
  imposed.impose_flux(b, 2e-6);
  imposed.step(p.centre, p.radius, p.cell.h, 1e-4);
  EXPECT_NEAR(reference.pressure_at(b) - reference.pressure()[0], imposed.pressure_at(b), 1e-9 * at_b);

  PeriodicFlow flow;
  flow.set_settings(settings(Vec3::Zero()));
  flow.impose_flux(b, 1e-6);
  EXPECT_EQ(flow.imposed_fluxes().size(), 1u);
  flow.clear_imposed_flux();
  flow.step(p.centre, p.radius, p.cell.h, 1e-4);
  EXPECT_LT(largest(flow.periodic_pressure()), 1e-12) << "cleared: nothing drives the flow";
  EXPECT_THROW(flow.impose_flux(b, NAN), std::invalid_argument);
}

TEST(PeriodicConditions, AResumedRunGoesOnAsTheUninterruptedOne) {
  // Spheres moving and the cell shearing, a compressible fluid and an imposed gradient: a second
  // engine resumed from the first's run state after two steps makes the third step bit for bit.
  Eigen::Matrix3d h = diagonal(1, 1.05, 0.95);
  const auto p = random_periodic(60, 53, h, 0.05, 0.08);
  const double dt = 1e-4;
  const auto positions = [&](int step, Eigen::Matrix3d& cell) {
    cell = h;
    cell(0, 1) += 1e-3 * step;
    std::vector<Vec3> x = p.centre;
    for (std::size_t s = 0; s < x.size(); ++s) x[s] += 2e-4 * step * Vec3(std::sin(s), std::cos(3.0 * s), 0.5);
    return x;
  };
  for (const double k : {0.0, 1e6}) {
    PeriodicFlow run;
    run.set_settings(settings(Vec3(0, 1, 0), k));
    Eigen::Matrix3d cell;
    for (int step = 0; step < 2; ++step) run.step(positions(step, cell), p.radius, cell, dt);
    const PeriodicFlow::RunState state = run.run_state();
    PeriodicFlow resumed;
    resumed.set_settings(settings(Vec3(0, 1, 0), k));
    resumed.resume(state);
    const auto x = positions(2, cell);
    run.step(x, p.radius, cell, dt);
    resumed.step(x, p.radius, cell, dt);
    ASSERT_EQ(resumed.periodic_pressure().size(), run.periodic_pressure().size());
    EXPECT_EQ(resumed.periodic_pressure(), run.periodic_pressure()) << "K " << k;
    EXPECT_EQ(resumed.volume_rates(), run.volume_rates()) << "K " << k;
    for (std::size_t s = 0; s < x.size(); ++s) EXPECT_EQ(resumed.forces()[s], run.forces()[s]);
    EXPECT_GT(largest(run.volume_rates()), 0) << "the spheres moved";
  }
}

TEST(PeriodicConditions, ABadRunStateIsRefusedAndChangesNothing) {
  const auto p = random_periodic(60, 54, diagonal(1, 1, 1), 0.05, 0.08);
  PeriodicFlow run;
  run.set_settings(settings(Vec3(1, 0, 0)));
  run.step(p.centre, p.radius, p.cell.h, 1e-4);
  const PeriodicFlow::RunState good = run.run_state();
  const std::vector<double> before = run.periodic_pressure();
  PeriodicFlow::RunState bad = good;
  bad.periodic_pressure.pop_back();
  EXPECT_THROW(run.resume(bad), std::invalid_argument);
  bad = good;
  bad.mesh_radii[3] = -1;
  EXPECT_THROW(run.resume(bad), std::invalid_argument);
  bad = good;
  bad.previous_centres.pop_back();
  EXPECT_THROW(run.resume(bad), std::invalid_argument);
  EXPECT_EQ(run.periodic_pressure(), before);
  EXPECT_EQ(run.remesh_count(), 1);
  PeriodicFlow fresh;
  EXPECT_THROW(fresh.run_state(), std::logic_error);
  EXPECT_THROW(fresh.resume(bad), std::invalid_argument);
  EXPECT_FALSE(fresh.has_mesh());
}
