#include "pfv/model/cell_conditions.hpp"

namespace pfv {

bool CellConditions::set_pressure(int cell, CellPressure p, int n_cells) {
  if (pressure_of(cell) == p) return false;
  if (pressure.empty()) pressure.assign(n_cells, CellPressure::kFollowBoundaries);
  pressure[cell] = p;
  return true;
}

bool CellConditions::block(int cell, int n_cells) {
  if (is_blocked(cell)) return false;
  if (blocked.empty()) blocked.assign(n_cells, 0);
  blocked[cell] = 1;
  return true;
}

}  // namespace pfv
