// The multigrid solver's start from its history of solutions (solution_history.hpp): in a
// drifting lattice its pressures stay within refinement_tolerance of the spread of the direct
// solve's at every step, across a changed time step, a remesh and a compressible fluid's rebuilt
// system; it needs fewer iterations than the start extrapolated linearly from the last two steps;
// a solution the caller drops leaves the history.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/linalg/amg_pcg.hpp"
#include "pfv/linalg/amg_solver.hpp"
#include "pfv/linalg/distributed_rows.hpp"
#include "pfv/linalg/solution_history.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

// m^3 spheres on a jittered cubic lattice filling the unit cube, and a drift velocity per sphere
// (random direction, 'speed' lattice spacings per unit time).
struct DriftingLattice {
  test::TestPacking packing;
  std::vector<Vec3> velocity;
};

DriftingLattice drifting_lattice(int m, unsigned seed, double speed) {
  DriftingLattice d;
  d.packing.walls.coord = {0, 1, 0, 1, 0, 1};
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> normal;
  const double h = 1.0 / m;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k) {
        d.packing.centre.emplace_back((i + 0.5 + 0.08 * u(gen)) * h, (j + 0.5 + 0.08 * u(gen)) * h,
                                      (k + 0.5 + 0.08 * u(gen)) * h);
        d.packing.radius.push_back((0.36 + 0.04 * u(gen)) * h);
        const Vec3 v(normal(gen), normal(gen), normal(gen));
        d.velocity.push_back(speed * h * v / v.norm());
      }
  return d;
}

std::vector<Vec3> positions_at(const DriftingLattice& d, double t) {
  std::vector<Vec3> x(d.packing.centre);
  for (std::size_t k = 0; k < x.size(); ++k) x[k] += t * d.velocity[k];
  return x;
}

double spread(const std::vector<double>& p) {
  const auto [lo, hi] = std::minmax_element(p.begin(), p.end());
  return *hi - *lo;
}

double largest_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

}  // namespace

// The engine's system of a drifting lattice (G fixed between remeshes, b from the volume rates)
// solved by AmgPcg two ways: the previous start, extrapolated linearly from the last two
// solutions, and the start from the history. Both keep the bound; the history's takes fewer
// iterations, and one per step once it holds three solutions with volume rates (the first step
// has none).
TEST(MultigridStart, TheHistoryNeedsFewerIterationsThanTheLinearStart) {
  const DriftingLattice d = drifting_lattice(18, 3, 0.2);
  FlowEngine direct = test::permeameter(1);
  direct.settings.solver = SolverKind::kCholesky;
  direct.settings.mixed_precision = false;
  direct.settings.mesh_update_interval = 1000000;
  const double dt = 1e-3, tolerance = direct.settings.refinement_tolerance;
  std::vector<std::vector<double>> b, reference;
  for (int step = 0; step < 10; ++step) {
    direct.step(positions_at(d, step * dt), d.packing.radius, d.packing.walls, dt);
    ASSERT_EQ(direct.remesh_count(), 1);
    b.push_back(direct.last_rhs());
    reference.push_back(direct.last_solution());
  }
  const DistributedRows rows = full_rows(*direct.system().matrix);
  AmgParameters linear = amg_parameters(MultigridSmoother::kGaussSeidel), history = linear;
  linear.start_history = 0;
  ASSERT_EQ(history.start_history, kEngineStartHistory);
  AmgPcg old_start(MPI_COMM_SELF, rows, linear), new_start(MPI_COMM_SELF, rows, history);
  std::vector<double> x_old(b[0].size(), 0.0), before(x_old), x_new(x_old);
  int old_total = 0, new_total = 0;
  std::string old_text, new_text;
  for (std::size_t k = 0; k < b.size(); ++k) {
    std::vector<double> start(x_old);
    if (k >= 2)  // the engine's start before the history: 2 p_n - p_n-1
      for (std::size_t i = 0; i < start.size(); ++i) start[i] = 2 * x_old[i] - before[i];
    before = x_old;
    x_old = start;
    const int old_iterations = old_start.solve(b[k], x_old, tolerance, 1000).iterations;
    const int new_iterations = new_start.solve(b[k], x_new, tolerance, 1000).iterations;
    const double bound = tolerance * spread(reference[k]);
    EXPECT_LE(largest_difference(x_old, reference[k]), bound) << "step " << k;
    EXPECT_LE(largest_difference(x_new, reference[k]), bound) << "step " << k;
    if (k >= 3) {
      old_total += old_iterations;
      new_total += new_iterations;
    }
    if (k >= 5) {
      EXPECT_EQ(new_iterations, 1) << "step " << k;
    }
    old_text += ' ' + std::to_string(old_iterations);
    new_text += ' ' + std::to_string(new_iterations);
  }
  EXPECT_LT(new_total, old_total);
  std::printf("iterations per step, linear start:%s; history:%s\n", old_text.c_str(), new_text.c_str());
}

// A solve whose solution the caller does not pass back (its step was dropped) leaves the history;
// one it passes back stays.
TEST(MultigridStart, ADroppedSolutionLeavesTheHistory) {
  const DriftingLattice d = drifting_lattice(8, 5, 0.2);
  FlowEngine direct = test::permeameter(1);
  direct.settings.solver = SolverKind::kCholesky;
  direct.settings.mixed_precision = false;
  std::vector<std::vector<double>> b;
  for (int step = 0; step < 3; ++step) {
    direct.step(positions_at(d, step * 1e-3), d.packing.radius, d.packing.walls, 1e-3);
    b.push_back(direct.last_rhs());
  }
  AmgPcg amg(MPI_COMM_SELF, full_rows(*direct.system().matrix), amg_parameters(MultigridSmoother::kGaussSeidel));
  std::vector<double> x1(b[0].size(), 0.0);
  amg.solve(b[0], x1, 1e-10, 1000);
  EXPECT_EQ(amg.kept_solutions(), 1);  // from zero: the start is not kept
  std::vector<double> x2(x1);
  amg.solve(b[1], x2, 1e-10, 1000);
  EXPECT_EQ(amg.kept_solutions(), 2);
  std::vector<double> x3(x1);  // step 2 dropped: the next starts from step 1's pressures again
  amg.solve(b[2], x3, 1e-10, 1000);
  EXPECT_EQ(amg.kept_solutions(), 2);  // x1 and x3, not x2
  std::vector<double> x4(x3);
  amg.solve(b[2], x4, 1e-10, 1000);
  EXPECT_EQ(amg.kept_solutions(), 3);
  std::vector<double> other(x4);  // pressures changed by the caller: the history starts from them
  other[0] += 1;
  amg.solve(b[2], other, 1e-10, 1000);
  EXPECT_EQ(amg.kept_solutions(), 2);
}

// The engine with multigrid against the direct solve, every sphere drifting at its own constant
// velocity: at every step within refinement_tolerance of the spread (the default 1e-10 and a loose
// 1e-4, where a solve stops after two updates), through a changed time step
// (extrapolated in time), a remesh (the history starts again on the new system from the
// interpolated pressures) and, for a compressible fluid, the rebuilt system a changed time step
// makes.
TEST(MultigridStart, KeepsTheBoundInADriftingLattice) {
  for (const auto& [bulk_modulus, tolerance] : {std::pair{0.0, 1e-10}, {1e3, 1e-10}, {0.0, 1e-4}, {1e3, 1e-4}}) {
    SCOPED_TRACE(std::to_string(bulk_modulus) + ", " + std::to_string(tolerance));
    const DriftingLattice d = drifting_lattice(18, 7, 0.2);
    FlowEngine direct = test::permeameter(1), multigrid = test::permeameter(1);
    direct.settings.solver = SolverKind::kCholesky;
    direct.settings.mixed_precision = false;
    multigrid.settings.solver = SolverKind::kMultigrid;
    for (FlowEngine* e : {&direct, &multigrid}) {
      e->settings.mesh_update_interval = 1000000;
      e->settings.fluid_bulk_modulus = bulk_modulus;
      e->settings.refinement_tolerance = tolerance;
    }
    double t = 0, worst_ratio = 0;
    std::string iterations;
    for (int step = 0; step < 16; ++step) {
      const double dt = step < 6 ? 1e-3 : 5e-4;  // the time step halves at step 6
      if (step == 11) {                          // and a remesh at step 11
        direct.request_remesh();
        multigrid.request_remesh();
      }
      t += dt;
      const std::vector<Vec3> x = positions_at(d, t);
      direct.step(x, d.packing.radius, d.packing.walls, dt);
      multigrid.step(x, d.packing.radius, d.packing.walls, dt);
      ASSERT_EQ(multigrid.pressure_solver()->kind(), SolverKind::kMultigrid);
      ASSERT_TRUE(multigrid.last_solve().converged) << "step " << step;
      const double bound = multigrid.settings.refinement_tolerance * spread(direct.pressure());
      const double error = largest_difference(multigrid.pressure(), direct.pressure());
      EXPECT_LE(error, bound) << "step " << step;
      worst_ratio = std::max(worst_ratio, error / bound);
      const int n = multigrid.last_solve().cg_iterations;
      // Incompressible: the history extrapolates in time through the change of dt (at most two
      // iterations) and predicts the step again, one iteration, three steps after the start and
      // after the remesh. (A compressible fluid's pressures relax from p = 0 through the run,
      // which no extrapolation predicts.)
      if (bulk_modulus == 0 && tolerance == 1e-10 &&
          (step == 5 || step == 9 || step == 10 || step == 14 || step == 15)) {
        EXPECT_EQ(n, 1) << "step " << step;
      }
      if (bulk_modulus == 0 && tolerance == 1e-10 && step >= 6 && step <= 8) {
        EXPECT_LE(n, 2) << "step " << step;
      }
      iterations += ' ' + std::to_string(n);
    }
    EXPECT_EQ(multigrid.remesh_count(), 2);
    std::printf("bulk modulus %g, tolerance %g: iterations per step%s; largest error %.2f x the bound\n", bulk_modulus,
                tolerance, iterations.c_str(), worst_ratio);
  }
}
