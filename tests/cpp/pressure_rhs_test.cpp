// The right-hand side and the flux balances of model/ over a pressure system built by hand,
// without a mesh or an engine: a chain of four cells, wall 0's Dirichlet cell, two unknowns, and
// wall 1's Dirichlet cell (pressure_rhs.hpp, flow_totals.hpp, boundary_source.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "pfv/model/flow_totals.hpp"
#include "pfv/model/pressure_rhs.hpp"

using namespace pfv;

namespace {

// 0 -(2)- 1 -(3)- 2 -(4)- 3, conductances in brackets.
PressureSystem chain() {
  PressureSystem s;
  s.source = {BoundarySource::wall(0), BoundarySource::unknown(), BoundarySource::unknown(), BoundarySource::wall(1)};
  s.unknown = {-1, 0, 1, -1};
  s.unknown_cell = {1, 2};
  s.adj_start = {0, 1, 3, 5, 6};
  s.adj_cell = {1, 0, 2, 1, 3, 2};
  s.adj_k = {2, 2, 3, 3, 4, 4};
  s.diagonal = {2, 5, 7, 4};
  return s;
}

}  // namespace

TEST(BoundarySource, NamedKinds) {
  EXPECT_TRUE(BoundarySource::unknown().is_unknown());
  EXPECT_TRUE(BoundarySource::wall(4).is_wall(4));
  EXPECT_FALSE(BoundarySource::wall(4).is_wall(3));
  EXPECT_TRUE(BoundarySource::imposed_point(2).takes_boundary_value());
  EXPECT_TRUE(BoundarySource::cell_imposed().imposes_pressure());
  EXPECT_FALSE(BoundarySource::cell_imposed().takes_boundary_value());
  EXPECT_FALSE(BoundarySource::blocked().imposes_pressure());
  EXPECT_TRUE(BoundarySource::blocked().is_blocked());
  EXPECT_EQ(BoundarySource::imposed_point(1), BoundarySource::imposed_point(1));
  EXPECT_NE(BoundarySource::imposed_point(1), BoundarySource::wall(1));
}

TEST(PressureRhs, DirichletValuesAndCouplings) {
  PressureSystem s = chain();
  s.source[2] = BoundarySource::imposed_point(0);  // values only: the unknowns are not renumbered here
  BoundaryConditions bc;
  bc.value[0] = 5;
  bc.value[1] = -1;
  bc.imposed_pressure.push_back({Vec3(0, 0, 0), 7});
  std::vector<double> p(4, 0.5);
  apply_dirichlet_values(s, bc, p);
  EXPECT_EQ(p, (std::vector<double>{5, 0.5, 7, -1}));

  const DirichletCouplings d = dirichlet_couplings(chain());
  EXPECT_EQ(d.unknown, (std::vector<int>{0, 1}));
  EXPECT_EQ(d.cell, (std::vector<int>{0, 3}));
  EXPECT_EQ(d.k, (std::vector<double>{2, 4}));
}

TEST(PressureRhs, AssemblesEveryTerm) {
  const PressureSystem s = chain();
  const DirichletCouplings d = dirichlet_couplings(s);
  const std::vector<double> rate{10, 1, 2, 20}, storage{0, 0.5, 0.25, 0}, before{0, 4, 8, 0};
  const std::vector<int> flux_cells{2, 0, -1};  // into an unknown, into a Dirichlet cell, nowhere
  const std::vector<PointCondition> flux{{Vec3(0, 0, 0), 3}, {Vec3(0, 0, 0), 100}, {Vec3(0, 0, 0), 1000}};
  const std::vector<double> boundary{6, 0, 0, -2};
  std::vector<double> rhs;
  assemble_rhs(s, RhsTerms{rate, {}, before, flux_cells, flux, d}, boundary, rhs);
  EXPECT_EQ(rhs, (std::vector<double>{-1 + 2 * 6, -2 + 3 + 4 * -2}));
  assemble_rhs(s, RhsTerms{rate, storage, before, flux_cells, flux, d}, boundary, rhs);
  EXPECT_EQ(rhs, (std::vector<double>{-1 + 0.5 * 4 + 2 * 6, -2 + 0.25 * 8 + 3 + 4 * -2}));
  EXPECT_EQ(imposed_flux_total(s, flux_cells, flux), 3);
}

TEST(PressureRhs, FieldWritesItsWallsCells) {
  const PressureSystem s = chain();
  const std::vector<Vec3> centre{Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0), Vec3(3, 0, 0)};
  int calls = 0;
  PressureField field;
  std::vector<double> values, p(4, 0.0);
  FieldCells cells;
  EXPECT_FALSE(apply_pressure_field(field, s, centre, cells, values, p));  // inactive
  field.wall = 1;
  field.evaluate = [&calls](const std::vector<Vec3>& at, std::vector<double>& out) {
    ++calls;
    out.clear();
    for (const Vec3& x : at) out.push_back(10 * x.x());
  };
  EXPECT_TRUE(apply_pressure_field(field, s, centre, cells, values, p));
  EXPECT_EQ(p, (std::vector<double>{0, 0, 0, 30}));
  EXPECT_EQ(cells.cells, (std::vector<int>{3}));
  field.wall = 2;  // no Dirichlet cell there: not evaluated
  EXPECT_FALSE(apply_pressure_field(field, s, centre, cells, values, p));
  EXPECT_EQ(calls, 1);
  field.wall = 0;
  field.evaluate = [](const std::vector<Vec3>&, std::vector<double>& out) {
    out.assign(1, std::numeric_limits<double>::quiet_NaN());
  };
  EXPECT_THROW(apply_pressure_field(field, s, centre, cells, values, p), std::invalid_argument);
  field.evaluate = [](const std::vector<Vec3>&, std::vector<double>& out) { out.assign(2, 1.0); };
  EXPECT_THROW(apply_pressure_field(field, s, centre, cells, values, p), std::invalid_argument);
}

TEST(FlowTotals, BoundaryFluxBalancesTheUnknowns) {
  const PressureSystem s = chain();
  // Steady flow from wall 0 (p = 9) to wall 1 (p = 0): conductances in series 2, 3, 4 carry
  // q = 9 / (1/2 + 1/3 + 1/4) = 9 * 12 / 13 through every throat.
  const double q = 9 * 12.0 / 13;
  const std::vector<double> p{9, 9 - q / 2, 9 - q / 2 - q / 3, 0};
  const std::vector<double> no_rates;
  EXPECT_NEAR(boundary_flux(s, p, no_rates, 0), -q, 1e-12);
  EXPECT_NEAR(boundary_flux(s, p, no_rates, 1), q, 1e-12);
  EXPECT_EQ(boundary_flux(s, p, no_rates, 2), 0);
  const std::vector<double> rates{0.5, 0, 0, -0.25};  // shrinking cells expel fluid through their wall
  EXPECT_NEAR(boundary_flux(s, p, rates, 0), -q - 0.5, 1e-12);
  EXPECT_NEAR(boundary_flux(s, p, rates, 1), q + 0.25, 1e-12);
  EXPECT_EQ(volume_rate_total(rates), 0.25);
  EXPECT_NEAR(average_pressure(p, {1, 1, 1, 1}), (p[0] + p[1] + p[2] + p[3]) / 4, 1e-12);
  EXPECT_EQ(average_pressure({}, {}), 0.0);
}
