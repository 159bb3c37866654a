#include "pfv/engine/flow_queries.hpp"

#include <stdexcept>

#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/flow_totals.hpp"

namespace pfv {

double boundary_flux(const FlowEngine& e, int wall) {
  return boundary_flux(e.system(), e.pressure(), e.volume_rates(), wall);
}

double imposed_flux_total(const FlowEngine& e) {
  return imposed_flux_total(e.system(), e.linear_system().imposed_flux_cells, e.bc.imposed_flux);
}

double volume_rate_total(const FlowEngine& e) { return volume_rate_total(e.volume_rates()); }

double average_pressure(const FlowEngine& e) {
  if (!e.has_mesh()) return 0.0;
  return average_pressure(e.pressure(), e.cells().volume);
}

double average_slice_pressure(const FlowEngine& e, int axis, double position) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("axis must be 0, 1 or 2");
  constexpr int kSamples = 40;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  const BoxWalls& walls = e.walls();
  const std::vector<double>& pressure = e.pressure();
  double sum = 0;
  int count = 0;
  for (int i = 0; i < kSamples; ++i)
    for (int j = 0; j < kSamples; ++j) {
      Vec3 x;
      x[axis] = position;
      x[a1] = walls.coord[2 * a1] + (i + 0.5) / kSamples * walls.extent(a1);
      x[a2] = walls.coord[2 * a2] + (j + 0.5) / kSamples * walls.extent(a2);
      const int c = locate(e, x);
      if (c < 0) continue;
      sum += pressure[c];
      ++count;
    }
  if (count == 0) throw std::invalid_argument("the slice lies outside the pore mesh");
  return sum / count;
}

bool cell_imposed(const FlowEngine& e, int cell) {
  const CellConditions& conditions = e.cell_conditions();
  switch (conditions.pressure_of(cell)) {
    case CellPressure::kImposed:
      return true;
    case CellPressure::kFree:
      return false;
    case CellPressure::kFollowBoundaries:
      break;
  }
  if (conditions.is_blocked(cell)) return false;
  const Mesh& m = e.mesh();
  for (int v : m.cell_vertices[cell])
    if (m.is_wall(v) && e.bc.is_pressure[m.wall_of(v)]) return true;
  for (const PointCondition& point : e.bc.imposed_pressure)  // as the next system will place them
    if (locate(e, point.position) == cell) return true;
  return false;
}

int locate(const FlowEngine& e, const Vec3& x) { return e.has_mesh() ? e.pore_mesh().tri.locate(x) : -1; }

bool metis_used(const FlowEngine& e) {
  const CholeskySolver* c = e.linear_system().cholesky();
  return c && c->factor().metis_used();
}

double refinement_contraction(const FlowEngine& e) {
  const CholeskySolver* c = e.linear_system().cholesky();
  return c ? c->refinement_contraction() : -1.0;
}

const std::string& solver_choice(const FlowEngine& e) { return e.linear_system().decision.choice; }

const StageTimes& system_times(const FlowEngine& e) { return e.linear_system().times; }

double mesh_viscosity(const FlowEngine& e) {
  return e.has_mesh() ? e.pore_mesh().viscosity() : e.settings.conductance.viscosity;
}

}  // namespace pfv
