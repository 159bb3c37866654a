// The flow model end to end on fixed packings: conductance law, solvers, conservation,
// force balance and the invariances the thesis states.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "pfv/model/conductance.hpp"
#include "test_packings.hpp"

using namespace pfv;
using test::permeameter;

TEST(Conductance, PoiseuilleForACircularTube) {
  // A throat with R_h = r/2 and A = pi r^2 must carry pi r^4 / (8 mu L).
  FacetGeometry f;
  const double r = 0.3, mu = 2.5, L = 1.7;
  f.cell = {{0, 1}};
  f.fluid_area = {M_PI * r * r};
  f.hydraulic_radius = {r / 2};
  f.length = {L};
  ConductanceModel m;
  m.viscosity = mu;
  m.clamp = false;
  EXPECT_NEAR(throat_conductances(f, m)[0], M_PI * std::pow(r, 4) / (8 * mu * L), 1e-15);
}

TEST(Conductance, DagansTubeWithTheEntranceTerm) {
  // With the orifice in series (entrance = 3 pi / 8), the same tube conducts Dagan, Weinberg &
  // Tamir's pi r^4 / (8 mu (L + 3 pi r / 8)); a flat throat (L = 0) keeps a finite conductance.
  FacetGeometry f;
  const double r = 0.3, mu = 2.5, L = 1.7;
  f.cell = {{0, 1}, {0, 1}};
  f.fluid_area = {M_PI * r * r, M_PI * r * r};
  f.hydraulic_radius = {r / 2, r / 2};
  f.length = {L, 0.0};
  ConductanceModel m;
  m.viscosity = mu;
  m.clamp = false;
  m.entrance = 3 * M_PI / 8;
  const auto k = throat_conductances(f, m);
  EXPECT_NEAR(k[0], M_PI * std::pow(r, 4) / (8 * mu * (L + 3 * M_PI * r / 8)), 1e-15);
  EXPECT_NEAR(k[1], std::pow(r, 3) / (3 * mu), 1e-15);  // Sampson's orifice alone
}

TEST(FlowModel, CholmodMatchesDenseSolve) {
  const auto p = test::random_packing(200, 21);
  FlowEngine e = permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const PressureSystem& s = e.system();
  const int n = s.n_unknowns();
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(n, n);
  for (int col = 0; col < n; ++col)
    for (int q = s.matrix->col_start[col]; q < s.matrix->col_start[col + 1]; ++q)
      G(s.matrix->row[q], col) = G(col, s.matrix->row[q]) = s.matrix->value[q];
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  for (int u = 0; u < n; ++u) {
    const int c = s.unknown_cell[u];
    for (int a = s.adj_start[c]; a < s.adj_start[c + 1]; ++a)
      if (s.unknown[s.adj_cell[a]] < 0) b[u] += s.adj_k[a] * e.pressure()[s.adj_cell[a]];
  }
  const Eigen::VectorXd x = G.ldlt().solve(b);
  for (int u = 0; u < n; ++u) EXPECT_NEAR(e.pressure()[s.unknown_cell[u]], x[u], 1e-10);
}

TEST(FlowModel, GaussSeidelConvergesToTheDirectSolution) {
  const auto p = test::random_packing(200, 22);
  FlowEngine direct = permeameter(0), gs = permeameter(0);
  gs.settings.solver = SolverKind::kGaussSeidel;
  gs.settings.tolerance = 1e-10;
  direct.step(p.centre, p.radius, p.walls, 1.0);
  gs.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_GT(gs.last_solve().sweeps, 1);
  for (std::size_t c = 0; c < direct.pressure().size(); ++c) EXPECT_NEAR(gs.pressure()[c], direct.pressure()[c], 1e-7);
}

TEST(FlowModel, InflowEqualsOutflow) {
  const auto p = test::random_packing(300, 23);
  for (int axis = 0; axis < 3; ++axis) {
    FlowEngine e = permeameter(axis);
    e.step(p.centre, p.radius, p.walls, 1.0);
    const double qin = boundary_flux(e, 2 * axis), qout = boundary_flux(e, 2 * axis + 1);
    EXPECT_LT(qin, 0);  // YADE's sign: inflow negative
    EXPECT_GT(qout, 0);
    EXPECT_LE(std::abs(qin + qout), 1e-8 * std::abs(qin));
  }
}

TEST(FlowModel, TotalForceOnSolidsIsPressureDropTimesArea) {
  const auto p = test::random_packing(300, 24);
  const double dp = 3.0;
  FlowEngine e = permeameter(2, dp);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const auto& F = e.forces();
  const int n = static_cast<int>(p.centre.size());
  Vec3 solid = Vec3::Zero();  // spheres plus the no-flux (lateral) walls
  for (int k = 0; k < n; ++k) solid += F[k];
  for (int w = 0; w < 4; ++w) solid += F[n + w];
  EXPECT_NEAR(solid.z(), dp * 1.0, 1e-7 * dp);
  EXPECT_NEAR(solid.x(), 0.0, 1e-10);
  EXPECT_NEAR(solid.y(), 0.0, 1e-10);
  // And the spheres alone carry the drop in the flow direction (lateral walls only push sideways).
  Vec3 spheres = Vec3::Zero();
  for (int k = 0; k < n; ++k) spheres += F[k];
  EXPECT_NEAR(spheres.z(), dp, 1e-7 * dp);
}

TEST(FlowModel, UniformPressureGivesNoNetForceOnSpheres) {
  const auto p = test::random_packing(250, 25);
  FlowEngine e;
  e.bc.is_pressure.fill(true);
  e.bc.value.fill(7.0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const int n = static_cast<int>(p.centre.size());
  for (int k = 0; k < n; ++k) EXPECT_LT(e.forces()[k].norm(), 1e-12);
  for (int w = 0; w < 6; ++w) {  // walls are pushed outwards by p times their area
    Vec3 expected = Vec3::Zero();
    expected[wall_axis(w)] = wall_is_max(w) ? 7.0 : -7.0;
    EXPECT_LT((e.forces()[n + w] - expected).norm(), 1e-12);
  }
}

TEST(FlowModel, ViscosityAndPermeabilityFactorScaleFluxesNotPressures) {
  const auto p = test::random_packing(200, 26);
  FlowEngine a = permeameter(0), b = permeameter(0);
  b.settings.conductance.viscosity = 7.0;
  b.settings.conductance.permeability_factor = 0.3;
  a.step(p.centre, p.radius, p.walls, 1.0);
  b.step(p.centre, p.radius, p.walls, 1.0);
  // Identical in exact arithmetic; the two factorisations differ by round-off times cond(G).
  for (std::size_t c = 0; c < a.pressure().size(); ++c) EXPECT_NEAR(a.pressure()[c], b.pressure()[c], 1e-10);
  for (std::size_t k = 0; k < a.forces().size(); ++k) EXPECT_LT((a.forces()[k] - b.forces()[k]).norm(), 1e-10);
  EXPECT_NEAR(boundary_flux(b, 1), boundary_flux(a, 1) * 0.3 / 7.0, 1e-12 * std::abs(boundary_flux(a, 1)));
}

TEST(FlowModel, CompressionExpelsExactlyTheVolumeLost) {
  // Shrink box and packing together (rigid spheres): the pore space loses the box volume lost,
  // the pressure rises, and the fluid leaving through the two drained walls is that volume.
  auto p = test::random_packing(250, 27);
  FlowEngine e;
  e.bc.is_pressure = {false, false, true, true, false, false};
  e.step(p.centre, p.radius, p.walls, 1e-3);
  const double s = 0.999;
  for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + s * (x - Vec3(0.5, 0.5, 0.5));
  for (double& w : p.walls.coord) w = 0.5 + s * (w - 0.5);
  e.step(p.centre, p.radius, p.walls, 1e-3);
  EXPECT_EQ(e.remesh_count(), 1);
  EXPECT_GT(average_pressure(e), 0);
  const double out = boundary_flux(e, 2) + boundary_flux(e, 3);
  EXPECT_NEAR(out, (1 - s * s * s) / 1e-3, 1e-8 * out);
  EXPECT_NEAR(out, -volume_rate_total(e), 1e-8 * out);
}

TEST(FlowModel, InternalRearrangementExpelsNothing) {
  // Spheres squeezed towards the centre inside fixed walls: pore volume moves from the middle
  // to the walls but its total is unchanged, so nothing leaves through the drained walls.
  auto p = test::random_packing(250, 27);
  FlowEngine e;
  e.bc.is_pressure = {false, false, true, true, false, false};
  e.step(p.centre, p.radius, p.walls, 1e-3);
  for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + 0.999 * (x - Vec3(0.5, 0.5, 0.5));
  e.step(p.centre, p.radius, p.walls, 1e-3);
  double pmax = 0;
  for (double x : e.pressure()) pmax = std::max(pmax, std::abs(x));
  EXPECT_GT(pmax, 0);
  const double each = std::max(std::abs(boundary_flux(e, 2)), std::abs(boundary_flux(e, 3)));
  EXPECT_GT(each, 0);                                                           // fluid does cross each drained wall...
  EXPECT_LT(std::abs(boundary_flux(e, 2) + boundary_flux(e, 3)), 1e-8 * each);  // ...but in equal amounts
}

TEST(FlowEngine, BadInputIsRejectedAndLeavesTheEngineUsable) {
  auto p = test::random_packing(100, 28);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const auto before = e.pressure();
  auto bad = p;
  bad.centre[5].x() = NAN;
  EXPECT_THROW(e.step(bad.centre, bad.radius, bad.walls, 1.0), std::invalid_argument);
  bad = p;
  bad.centre[7].y() = 1.5;
  EXPECT_THROW(e.step(bad.centre, bad.radius, bad.walls, 1.0), std::invalid_argument);
  bad = p;
  bad.centre[3] = bad.centre[4];
  e.request_remesh();
  EXPECT_THROW(e.step(bad.centre, bad.radius, bad.walls, 1.0), std::invalid_argument);
  bad = p;
  bad.centre[3] = bad.centre[4] + Vec3(0.5 * bad.radius[4], 0, 0);
  e.request_remesh();
  EXPECT_THROW(e.step(bad.centre, bad.radius, bad.walls, 1.0), std::invalid_argument);
  e.step(p.centre, p.radius, p.walls, 1.0);
  ASSERT_EQ(e.pressure().size(), before.size());
  for (std::size_t c = 0; c < before.size(); ++c) EXPECT_NEAR(e.pressure()[c], before[c], 1e-12);
}

TEST(FlowEngine, NoPressureBoundaryIsASingularSystem) {
  const auto p = test::random_packing(50, 29);
  FlowEngine e;
  try {
    e.step(p.centre, p.radius, p.walls, 1.0);
    FAIL() << "expected a singular-system error";
  } catch (const std::domain_error& err) {
    EXPECT_NE(std::string(err.what()).find("no boundary has an imposed pressure"), std::string::npos);
  }
}

TEST(FlowEngine, RemeshTriggers) {
  auto p = test::random_packing(150, 30);
  FlowEngine e = permeameter(0);
  e.settings.mesh_update_interval = 3;
  for (int i = 0; i < 7; ++i) e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.remesh_count(), 3);  // steps 1, 4 and 7

  // Cumulative pore strain: each shrink changes pore volumes by a few per mille; the
  // threshold is crossed after a few steps, not at every step and not never.
  FlowEngine s = permeameter(0);
  s.settings.mesh_update_interval = 0;
  s.settings.def_tolerance = 0.02;
  s.step(p.centre, p.radius, p.walls, 1.0);
  int remeshes_seen = 1;
  for (int i = 0; i < 12; ++i) {
    for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + 0.999 * (x - Vec3(0.5, 0.5, 0.5));
    s.step(p.centre, p.radius, p.walls, 1.0);
    remeshes_seen = s.remesh_count();
  }
  EXPECT_GT(remeshes_seen, 1);
  EXPECT_LT(remeshes_seen, 12);

  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.remesh_count(), 4);
}

TEST(FlowEngine, BackgroundRemeshArrivesLateButCorrect) {
  auto p = test::random_packing(300, 31);
  FlowEngine fg = permeameter(0), bg = permeameter(0);
  for (FlowEngine* e : {&fg, &bg}) e->settings.mesh_update_interval = 5;
  bg.settings.background_remesh = true;
  for (int i = 0; i < 40; ++i) {
    for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + 0.9999 * (x - Vec3(0.5, 0.5, 0.5));
    fg.step(p.centre, p.radius, p.walls, 1e-3);
    bg.remesher().wait();  // deterministic: a remesh launched at step k is adopted at k+1
    bg.step(p.centre, p.radius, p.walls, 1e-3);
    for (double x : bg.pressure()) ASSERT_TRUE(std::isfinite(x));
    // Conservation holds on whichever mesh is in use: outflow = volume lost by the unknowns.
    const double out = boundary_flux(bg, 0) + boundary_flux(bg, 1);
    EXPECT_NEAR(out, -volume_rate_total(bg), 1e-8 * std::abs(boundary_flux(bg, 0)));
  }
  EXPECT_EQ(bg.remesh_count(), fg.remesh_count());  // every remesh was adopted, one step late
  // A mesh a few steps old changes the pressure little (the accuracy caveat of YADE's multithread).
  double dmax = 0;
  for (int k = 0; k < static_cast<int>(p.centre.size()); ++k)
    dmax = std::max(dmax, (fg.forces()[k] - bg.forces()[k]).norm());
  double fmax = 0;
  for (const auto& f : fg.forces()) fmax = std::max(fmax, f.norm());
  EXPECT_LT(dmax, 0.05 * fmax);
}

TEST(FlowEngine, FailedBackgroundRemeshSurfacesAndRecovers) {
  auto p = test::random_packing(150, 32);
  FlowEngine e = permeameter(0);
  e.settings.mesh_update_interval = 2;
  e.settings.background_remesh = true;
  e.step(p.centre, p.radius, p.walls, 1.0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  auto bad = p;
  // A radius so large that a neighbour's centre lies inside: only a remesh can see it (the
  // centres have not moved, so no cell is turned inside out either).
  bad.radius[1] = 0.5;
  e.step(bad.centre, bad.radius, bad.walls, 1.0);  // launches the background remesh
  e.remesher().wait();
  try {
    e.step(p.centre, p.radius, p.walls, 1.0);
    FAIL() << "the background remesh should have failed";
  } catch (const std::invalid_argument& err) {
    EXPECT_NE(std::string(err.what()).find("inside the other sphere"), std::string::npos) << err.what();
  }
  const int before = e.remesh_count();
  e.step(p.centre, p.radius, p.walls, 1.0);  // foreground remesh of the good scene
  EXPECT_EQ(e.remesh_count(), before + 1);
  const double out = boundary_flux(e, 0) + boundary_flux(e, 1);
  EXPECT_NEAR(out, -volume_rate_total(e), 1e-8 * std::abs(boundary_flux(e, 0)));
}

TEST(FlowModel, PreconditionedCgMatchesDirectAndWarmStartPays) {
  auto p = test::random_packing(300, 33);
  FlowEngine direct = permeameter(1), cg = permeameter(1);
  cg.settings.solver = SolverKind::kConjugateGradient;
  cg.settings.tolerance = 1e-12;
  direct.step(p.centre, p.radius, p.walls, 1e-3);
  cg.step(p.centre, p.radius, p.walls, 1e-3);
  for (std::size_t c = 0; c < direct.pressure().size(); ++c) EXPECT_NEAR(cg.pressure()[c], direct.pressure()[c], 1e-9);
  const int cold = cg.last_solve().cg_iterations;
  // A small deformation: the warm start from the previous pressures needs fewer iterations.
  for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + 0.99999 * (x - Vec3(0.5, 0.5, 0.5));
  direct.step(p.centre, p.radius, p.walls, 1e-3);
  cg.step(p.centre, p.radius, p.walls, 1e-3);
  EXPECT_LT(cg.last_solve().cg_iterations, cold);
  for (std::size_t c = 0; c < direct.pressure().size(); ++c)
    EXPECT_NEAR(cg.pressure()[c], direct.pressure()[c], 1e-9 * (1 + std::abs(direct.pressure()[c])));
}

TEST(FlowModel, CompressibleFluidInAClosedBoxFollowsTheBulkModulus) {
  // Undrained compression of rigid spheres, no pressure boundary: the fluid stored,
  // sum_i V_f,i p_i / K, equals the volume lost, and once the pressure has equalised it is
  // p = K * (volume lost) / (fluid volume).
  auto p = test::random_packing(200, 34);
  FlowEngine e;
  // A soft fluid (air-water mixture): storage and conductance terms of similar size, so the
  // identities below hold to round-off (with water's 2.2e9 the system is ill-conditioned).
  const double K = 1e5;
  e.settings.fluid_bulk_modulus = K;
  e.settings.mesh_update_interval = 0;
  e.step(p.centre, p.radius, p.walls, 1e-4);
  const double s = 0.999;
  for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + s * (x - Vec3(0.5, 0.5, 0.5));
  for (double& w : p.walls.coord) w = 0.5 + s * (w - 0.5);
  e.step(p.centre, p.radius, p.walls, 1e-4);
  const auto& vf = e.cells().fluid_volume;
  double stored = 0, fluid = 0;
  for (std::size_t c = 0; c < vf.size(); ++c) {
    stored += vf[c] * e.pressure()[c] / K;
    fluid += vf[c];
  }
  const double lost = 1.0 - s * s * s;  // box volume lost (the spheres are rigid)
  EXPECT_NEAR(stored, lost, 1e-9 * lost);
  // Without motion the pressure diffuses towards K * lost / fluid, storing the same volume.
  auto spread = [&] {
    const auto [lo, hi] = std::minmax_element(e.pressure().begin(), e.pressure().end());
    return *hi - *lo;
  };
  const double initial_spread = spread();
  for (int i = 0; i < 20; ++i) e.step(p.centre, p.radius, p.walls, 1e-3);
  stored = 0;
  for (std::size_t c = 0; c < vf.size(); ++c) stored += vf[c] * e.pressure()[c] / K;
  EXPECT_NEAR(stored, lost, 1e-9 * lost);
  EXPECT_LT(spread(), 0.1 * initial_spread);
  EXPECT_NEAR(average_pressure(e), K * lost / fluid, 0.05 * K * lost / fluid);
  (void)fluid;
}

TEST(FlowModel, StiffFluidTendsToTheIncompressibleSolution) {
  auto p = test::random_packing(200, 35);
  FlowEngine inc = permeameter(1), comp = permeameter(1);
  comp.settings.fluid_bulk_modulus = 1e20;
  for (FlowEngine* e : {&inc, &comp}) e->step(p.centre, p.radius, p.walls, 1e-3);
  for (auto& x : p.centre) x = Vec3(0.5, 0.5, 0.5) + 0.9999 * (x - Vec3(0.5, 0.5, 0.5));
  for (FlowEngine* e : {&inc, &comp}) e->step(p.centre, p.radius, p.walls, 1e-3);
  double pmax = 0;
  for (double x : inc.pressure()) pmax = std::max(pmax, std::abs(x));
  for (std::size_t c = 0; c < inc.pressure().size(); ++c)
    EXPECT_NEAR(comp.pressure()[c], inc.pressure()[c], 1e-6 * pmax);
}
