// Conditions set on single cells (imposed, freed, blocked), the per-cell queries (flux,
// barycentre, stored pore volume) and the volume updates of YADE's updateVolumes and
// initializeVolumes, against conservation and the definitions they state.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/flow_queries.hpp"
#include "pfv/model/cell_queries.hpp"
#include "test_packings.hpp"

using namespace pfv;
using test::permeameter;

namespace {

// The interior cell nearest the point (no wall vertex).
int interior_cell_near(const FlowEngine& e, const Vec3& x) {
  int best = -1;
  double d = 1e300;
  for (int c = 0; c < e.mesh().n_cells(); ++c) {
    if (e.cells().shape[c].n_walls) continue;
    const double dc = (e.cells().power_centre[c] - x).norm();
    if (dc < d) {
      d = dc;
      best = c;
    }
  }
  return best;
}

double sum_of_fluxes_where(const FlowEngine& e, bool dirichlet) {
  double q = 0;
  for (int c = 0; c < e.mesh().n_cells(); ++c)
    if ((e.system().unknown[c] < 0) == dirichlet) q += cell_flux(e.system(), e.pressure(), e.volume_rates(), c);
  return q;
}

}  // namespace

TEST(CellConditions, ImposedCellKeepsThePressureSetOnIt) {
  const auto p = test::random_packing(250, 81);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const int c = interior_cell_near(e, Vec3(0.5, 0.5, 0.5));
  ASSERT_GE(c, 0);
  EXPECT_FALSE(cell_imposed(e, c));
  e.set_cell_pressure(c, 0.9);  // above the solution there (about 0.5): the cell becomes a source
  e.set_cell_imposed(c, true);
  EXPECT_TRUE(cell_imposed(e, c));
  const int systems = e.system_builds();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.system_builds(), systems + 1);
  EXPECT_EQ(e.remesh_count(), 1);
  EXPECT_EQ(e.pressure()[c], 0.9);
  EXPECT_LT(e.system().unknown[c], 0);
  // Its flux is what it injects: out through the two pressure walls, and nowhere else.
  const double q = cell_flux(e.system(), e.pressure(), e.volume_rates(), c);
  EXPECT_GT(q, 0);
  EXPECT_NEAR(q, boundary_flux(e, 0) + boundary_flux(e, 1), 1e-9 * q);
  // Freeing it again restores the permeameter.
  e.set_cell_imposed(c, false);
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_GE(e.system().unknown[c], 0);
  EXPECT_NEAR(boundary_flux(e, 0) + boundary_flux(e, 1), 0, 1e-9 * std::abs(boundary_flux(e, 1)));
}

TEST(CellConditions, FreedWallCellIsAnUnknown) {
  const auto p = test::random_packing(250, 82);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  int c = -1;
  for (int k = 0; k < e.mesh().n_cells() && c < 0; ++k)
    if (e.system().source[k].is_wall(0)) c = k;
  ASSERT_GE(c, 0);
  EXPECT_TRUE(cell_imposed(e, c));
  EXPECT_EQ(e.pressure()[c], 1.0);
  e.set_cell_imposed(c, false);
  EXPECT_FALSE(cell_imposed(e, c));
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_GE(e.system().unknown[c], 0);
  EXPECT_LT(e.pressure()[c], 1.0);
  EXPECT_GT(e.pressure()[c], 0.0);
}

TEST(CellConditions, FluxesOfUnknownsVanishAndThoseOfDirichletCellsAreTheBoundaryFluxes) {
  const auto p = test::random_packing(300, 83);
  FlowEngine e = permeameter(1);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const double scale = std::abs(boundary_flux(e, 2));
  for (int c = 0; c < e.mesh().n_cells(); ++c) {
    if (e.system().unknown[c] < 0) continue;
    EXPECT_LT(std::abs(cell_flux(e.system(), e.pressure(), e.volume_rates(), c)), 1e-9 * scale);
  }
  for (int w : {2, 3}) {
    double q = 0;
    for (int c = 0; c < e.mesh().n_cells(); ++c)
      if (e.system().source[c].is_wall(w)) q += cell_flux(e.system(), e.pressure(), e.volume_rates(), c);
    EXPECT_NEAR(-q, boundary_flux(e, w), 1e-12 * scale);
  }
}

TEST(CellConditions, BlockedCellsCarryNoFlux) {
  const auto p = test::random_packing(300, 84);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const double open = boundary_flux(e, 1);
  const int a = interior_cell_near(e, Vec3(0.4, 0.5, 0.5)), b = interior_cell_near(e, Vec3(0.6, 0.5, 0.5));
  const double pa = e.pressure()[a];
  e.block_cell(a, false);
  e.block_cell(b, true);
  EXPECT_EQ(e.pressure()[b], 0.0);
  EXPECT_FALSE(cell_imposed(e, a));
  EXPECT_TRUE(cell_imposed(e, b));
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.pressure()[a], pa);  // kept as it was
  EXPECT_EQ(e.pressure()[b], 0.0);
  for (int c : {a, b})
    for (int x = e.system().adj_start[c]; x < e.system().adj_start[c + 1]; ++x) EXPECT_EQ(e.system().adj_k[x], 0.0);
  // The permeameter still conserves mass, and carries less with two pores shut.
  EXPECT_NEAR(boundary_flux(e, 0) + boundary_flux(e, 1), 0, 1e-9 * open);
  EXPECT_LT(boundary_flux(e, 1), open);
  EXPECT_LT(std::abs(sum_of_fluxes_where(e, false)), 1e-8 * open);
  // A remesh renumbers the cells: the conditions are gone.
  e.request_remesh();
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_TRUE(e.cell_conditions().empty());
  EXPECT_NEAR(boundary_flux(e, 1), open, 1e-9 * open);
}

TEST(CellConditions, ASettingThatChangesNothingRebuildsNothing) {
  const auto p = test::random_packing(150, 85);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const int c = interior_cell_near(e, Vec3(0.5, 0.5, 0.5));
  e.set_cell_imposed(c, true);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const int systems = e.system_builds();
  e.set_cell_imposed(c, true);
  e.set_cell_pressure(c, 0.3);  // a value, not a condition: no rebuild
  e.step(p.centre, p.radius, p.walls, 1.0);
  EXPECT_EQ(e.system_builds(), systems);
  EXPECT_EQ(e.pressure()[c], 0.3);
  EXPECT_THROW(e.set_cell_pressure(c, std::nan("")), std::invalid_argument);
}

TEST(CellQueries, DirichletFluxesSumToTheVolumeChange) {
  // Moving spheres inside fixed walls: the Dirichlet cells' fluxes sum to the total dV/dt.
  auto p = test::random_packing(250, 86);
  FlowEngine e;
  e.bc.is_pressure = {false, false, true, true, false, false};
  e.step(p.centre, p.radius, p.walls, 1e-3);
  for (std::size_t k = 0; k < p.centre.size(); ++k) p.centre[k].x() += 1e-4 * std::sin(3.0 * k);
  e.step(p.centre, p.radius, p.walls, 1e-3);
  const double rates = volume_rate_total(e);
  double scale = 0;
  for (double r : e.volume_rates()) scale += std::abs(r);
  ASSERT_GT(scale, 0);
  EXPECT_NEAR(sum_of_fluxes_where(e, true) + sum_of_fluxes_where(e, false), rates, 1e-9 * scale);
  EXPECT_NEAR(sum_of_fluxes_where(e, false), 0, 1e-9 * scale);
}

TEST(CellQueries, BarycentreIsTheVertexMeanAndLiesInsideTheWalls) {
  const auto p = test::random_packing(200, 87);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const Packing pk{p.centre, p.radius, p.walls};
  for (int c = 0; c < e.mesh().n_cells(); ++c) {
    const CellShape& s = e.cells().shape[c];
    const Vec3 g = cell_barycenter(s, pk);
    for (int w = 0; w < kWallCount; ++w) EXPECT_GE(p.walls.height(w, g), 0);
    if (s.n_walls == 0) {
      const Vec3 mean = (p.centre[s.v[0]] + p.centre[s.v[1]] + p.centre[s.v[2]] + p.centre[s.v[3]]) / 4.0;
      EXPECT_LT((g - mean).norm(), 1e-15);
    } else if (s.n_walls == 1) {  // the wall vertex at the foot of the sphere mean
      const int w = s.v[3];
      const Vec3 m = (p.centre[s.v[0]] + p.centre[s.v[1]] + p.centre[s.v[2]]) / 3.0;
      EXPECT_NEAR(p.walls.height(w, g), 0.75 * p.walls.height(w, m), 1e-14);
    }
  }
}

TEST(CellQueries, VoidVolumesAreFluidVolumesFlooredByTheMinimumPorosity) {
  const auto p = test::random_packing(200, 88);
  FlowEngine e = permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1.0);
  const auto plain = e.void_volumes();
  for (std::size_t c = 0; c < plain.size(); ++c) EXPECT_EQ(plain[c], e.cells().fluid_volume[c]);
  e.settings.minimum_porosity = 0.99;  // the loose random packing: most cells are more porous
  const auto floored = e.void_volumes();
  int raised = 0;
  for (std::size_t c = 0; c < plain.size(); ++c) {
    EXPECT_EQ(floored[c], std::max(plain[c], 0.99 * e.cells().volume[c]));
    raised += floored[c] > plain[c];
  }
  EXPECT_GT(raised, 0);
  e.settings.minimum_porosity = 1.0;
  EXPECT_THROW(validate(e.settings), std::invalid_argument);
}

TEST(CellQueries, MinimumPorosityRebuildsACompressibleSystemOnly) {
  const auto p = test::random_packing(150, 89);
  for (const double bulk : {0.0, 1e5}) {
    FlowEngine e = permeameter(0);
    e.settings.fluid_bulk_modulus = bulk;
    e.step(p.centre, p.radius, p.walls, 1e-3);
    const int systems = e.system_builds();
    e.settings.minimum_porosity = 0.3;
    e.step(p.centre, p.radius, p.walls, 1e-3);
    EXPECT_EQ(e.system_builds(), systems + (bulk > 0 ? 1 : 0));
  }
}

TEST(CellVolumes, UpdateVolumesMeasuresTheRatesAndMovesTheReference) {
  auto p = test::random_packing(200, 90);
  FlowEngine e;
  e.bc.is_pressure = {false, false, true, true, false, false};
  e.step(p.centre, p.radius, p.walls, 1e-3);
  auto moved = p;
  for (std::size_t k = 0; k < moved.centre.size(); ++k) moved.centre[k].y() += 2e-4 * std::cos(2.0 * k);
  FlowEngine f;
  f.bc = e.bc;
  f.step(p.centre, p.radius, p.walls, 1e-3);
  // Through update_volumes: the rates of the motion, then no rate at the same positions.
  e.update_volumes(moved.centre, moved.walls, 1e-3);
  f.step(moved.centre, moved.radius, moved.walls, 1e-3);  // the same motion in a step
  ASSERT_EQ(e.volume_rates().size(), f.volume_rates().size());
  for (std::size_t c = 0; c < f.volume_rates().size(); ++c)
    EXPECT_NEAR(e.volume_rates()[c], f.volume_rates()[c], 1e-9 * (std::abs(f.volume_rates()[c]) + 1e-9));
  e.step(moved.centre, moved.radius, moved.walls, 1e-3);
  for (double r : e.volume_rates()) EXPECT_EQ(r, 0.0);
  EXPECT_THROW(e.update_volumes(std::vector<Vec3>(3, Vec3(0.5, 0.5, 0.5)), p.walls, 1e-3), std::invalid_argument);
  EXPECT_THROW(e.update_volumes(p.centre, p.walls, 0.0), std::invalid_argument);
}

TEST(CellVolumes, InitializeVolumesMeasuresThePoresAgainAndDropsTheNextRate) {
  auto p = test::random_packing(200, 91);
  FlowEngine e;
  e.bc.is_pressure = {false, false, true, true, false, false};
  e.step(p.centre, p.radius, p.walls, 1e-3);
  const auto at_mesh = e.void_volumes();
  auto moved = p;
  for (std::size_t k = 0; k < moved.centre.size(); ++k) moved.centre[k].z() += 2e-4 * std::sin(5.0 * k);
  e.initialize_volumes(moved.centre, moved.walls);
  const auto measured = e.void_volumes();
  double change = 0;
  for (int c = 0; c < e.mesh().n_cells(); ++c) {
    const double v = cell_volume(e.cells().shape[c], moved.centre, moved.walls);
    EXPECT_NEAR(measured[c], std::max(0.0, v - (e.cells().volume[c] - e.cells().fluid_volume[c])), 1e-15);
    change += std::abs(measured[c] - at_mesh[c]);
  }
  EXPECT_GT(change, 0);
  e.step(moved.centre, moved.radius, moved.walls, 1e-3);
  EXPECT_EQ(volume_rate_total(e), 0.0);  // no dV/dt term in the step after
  e.request_remesh();
  e.step(moved.centre, moved.radius, moved.walls, 1e-3);
  const auto remeshed = e.void_volumes();
  for (int c = 0; c < e.mesh().n_cells(); ++c) EXPECT_EQ(remeshed[c], e.cells().fluid_volume[c]);
}
