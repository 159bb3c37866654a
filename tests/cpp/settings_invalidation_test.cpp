// A settings change through the C++ API rebuilds what the table in
// tests/data/settings_invalidation.csv says; tests/yade/engine/test_settings_invalidation.py checks the
// same table through the Python bindings and through pfv.FlowEngine.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/engine/solver_policy.hpp"
#include "test_packings.hpp"

using namespace pfv;

namespace {

struct Row {
  std::string core, rebuild;
};

// The first and last fields of each data line (the others are for the Python test).
std::vector<Row> read_table() {
  std::ifstream in(std::string(PFV_TEST_DATA_DIR) + "/settings_invalidation.csv");
  std::vector<Row> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    rows.push_back({line.substr(0, line.find(',')), line.substr(line.rfind(',') + 1)});
  }
  return rows;
}

// The C++ side of each row: the field behind the binding of that name.
const std::map<std::string, std::function<void(FlowEngine&)>>& edits() {
  static const std::map<std::string, std::function<void(FlowEngine&)>> table{
      {"permeability_factor", [](FlowEngine& e) { e.settings.conductance.permeability_factor = 2.0; }},
      {"clamp_k_values", [](FlowEngine& e) { e.settings.conductance.clamp = false; }},
      {"conductance_entrance", [](FlowEngine& e) { e.settings.conductance.entrance = 1.0; }},
      {"min_k_div_k_mean", [](FlowEngine& e) { e.settings.conductance.min_ratio = 1e-3; }},
      {"max_k_div_k_mean", [](FlowEngine& e) { e.settings.conductance.max_ratio = 50.0; }},
      {"slip_boundary", [](FlowEngine& e) { e.settings.slip_boundary = false; }},
      {"yade_wall_throat_factor", [](FlowEngine& e) { e.settings.yade_wall_throat_factor = false; }},
      {"viscous_shear", [](FlowEngine& e) { e.settings.viscous_shear = true; }},
      {"viscosity", [](FlowEngine& e) { e.settings.conductance.viscosity = 2.0; }},
      {"solver", [](FlowEngine& e) { e.settings.solver = SolverKind::kConjugateGradient; }},
      {"ordering", [](FlowEngine& e) { e.settings.ordering = Ordering::kAmd; }},
      {"force_metis", [](FlowEngine& e) { e.settings.force_metis = true; }},
      {"mixed_precision", [](FlowEngine& e) { e.settings.mixed_precision = false; }},
      {"mixed_precision_min_entries", [](FlowEngine& e) { e.settings.mixed_precision_min_entries = 0; }},
      {"max_factor_bytes", [](FlowEngine& e) { e.settings.max_factor_bytes = 1e4; }},
      {"multigrid_smoother", [](FlowEngine& e) { e.settings.multigrid_smoother = MultigridSmoother::kJacobi; }},
      {"fluid_bulk_modulus", [](FlowEngine& e) { e.settings.fluid_bulk_modulus = 1e5; }},
      {"bnd_is_pressure", [](FlowEngine& e) { e.bc.is_pressure = {true, true, true, false, false, false}; }},
      {"impose_pressure",
       [](FlowEngine& e) {
         e.bc.imposed_pressure.push_back({Vec3(0.5, 0.5, 0.5), 0.3});
       }},
      {"impose_flux",
       [](FlowEngine& e) {
         e.bc.imposed_flux.push_back({Vec3(0.5, 0.5, 0.5), -1e-3});
       }},
      {"set_cell_imposed", [](FlowEngine& e) { e.set_cell_imposed(0, true); }},
      {"block_cell", [](FlowEngine& e) { e.block_cell(0, false); }},
      {"pressure_profile",
       [](FlowEngine& e) {
         e.bc.profile = {3, 0, {0.0, 1.0}, {0.0, 1.0}};
       }},
      {"bnd_value", [](FlowEngine& e) { e.bc.value = {1.0, 0.5, 0, 0, 0, 0}; }},
      {"tolerance", [](FlowEngine& e) { e.settings.tolerance = 1e-8; }},
      {"relax", [](FlowEngine& e) { e.settings.relax = 1.5; }},
      {"max_iterations", [](FlowEngine& e) { e.settings.max_iterations = 1000; }},
      {"refinement_tolerance", [](FlowEngine& e) { e.settings.refinement_tolerance = 1e-9; }},
      {"reuse_ordering", [](FlowEngine& e) { e.settings.reuse_ordering = false; }},
      {"cholmod_openmp_teams", [](FlowEngine& e) { e.settings.cholmod_openmp_teams = true; }},
      {"def_tolerance", [](FlowEngine& e) { e.settings.def_tolerance = 0.5; }},
      {"p_zero", [](FlowEngine& e) { e.settings.p_zero = 1.0; }},
      {"fluid_density", [](FlowEngine& e) { e.settings.fluid_density = 1000.0; }},
      {"gravity", [](FlowEngine& e) { e.settings.gravity = Vec3(0.0, -9.81, 0.0); }},
      {"minimum_porosity", [](FlowEngine& e) { e.settings.minimum_porosity = 0.1; }},
      {"flat_threshold", [](FlowEngine& e) { e.settings.flat_threshold = 1e-6; }},
      {"volume_correction", [](FlowEngine& e) { e.settings.volume_correction = 0.5; }},
      {"shear_viscosity", [](FlowEngine& e) { e.settings.shear_viscosity = 1e-3; }},
      {"interpolate_on_remesh", [](FlowEngine& e) { e.settings.interpolate_on_remesh = true; }},
      {"set_cell_pressure", [](FlowEngine& e) { e.set_cell_pressure(0, 0.5); }},
      {"background_remesh", [](FlowEngine& e) { e.settings.background_remesh = true; }},
  };
  return table;
}

}  // namespace

TEST(SettingsInvalidation, EachChangeRebuildsWhatTheTableSays) {
  const std::vector<Row> rows = read_table();
  ASSERT_EQ(rows.size(), edits().size()) << "the table and the C++ edits list different settings";
  const auto p = test::random_packing(150, 61);
  for (const Row& row : rows) {
    SCOPED_TRACE(row.core);
    const auto edit = edits().find(row.core);
    ASSERT_NE(edit, edits().end()) << "no C++ edit for " << row.core;
    // The small bound makes auto take multigrid, which a build without hypre does not have.
    if (row.core == "max_factor_bytes" && !solver_unavailable(SolverKind::kMultigrid).empty()) continue;
    FlowEngine e = test::permeameter(0);
    e.step(p.centre, p.radius, p.walls, 1e-3);
    e.step(p.centre, p.radius, p.walls, 1e-3);
    const int remeshes = e.remesh_count(), systems = e.system_builds();
    edit->second(e);
    e.step(p.centre, p.radius, p.walls, 1e-3);
    const int new_remeshes = e.remesh_count() - remeshes, new_systems = e.system_builds() - systems;
    const std::string seen = new_remeshes > 0 ? "remesh" : new_systems > 0 ? "system" : "none";
    EXPECT_EQ(seen, row.rebuild);
    EXPECT_LE(new_remeshes, 1);
    EXPECT_LE(new_systems, 1);  // a remesh builds its system once
    // Nothing is rebuilt twice: the next step with the same settings rebuilds nothing.
    e.step(p.centre, p.radius, p.walls, 1e-3);
    EXPECT_EQ(e.remesh_count() - remeshes, new_remeshes);
    EXPECT_EQ(e.system_builds() - systems, new_systems);
  }
}

TEST(SettingsInvalidation, CompressibleFluidRebuildsItsSystemWhenTheTimeStepChanges) {
  const auto p = test::random_packing(150, 62);
  FlowEngine e = test::permeameter(0);
  e.settings.fluid_bulk_modulus = 1e5;
  e.step(p.centre, p.radius, p.walls, 1e-3);
  const int systems = e.system_builds();
  e.step(p.centre, p.radius, p.walls, 1e-3);
  EXPECT_EQ(e.system_builds(), systems);
  e.step(p.centre, p.radius, p.walls, 2e-3);
  EXPECT_EQ(e.system_builds(), systems + 1);
  EXPECT_EQ(e.remesh_count(), 1);
}

TEST(SettingsInvalidation, AnInvalidSettingIsRefusedAndTheEngineUnchanged) {
  const auto p = test::random_packing(150, 63);
  FlowEngine e = test::permeameter(0);
  e.step(p.centre, p.radius, p.walls, 1e-3);
  const std::vector<double> before = e.pressure();
  e.settings.relax = 2.5;
  EXPECT_THROW(e.step(p.centre, p.radius, p.walls, 1e-3), std::invalid_argument);
  EXPECT_EQ(e.pressure(), before);
  e.settings.relax = 1.9;
  EXPECT_NO_THROW(e.step(p.centre, p.radius, p.walls, 1e-3));
}
