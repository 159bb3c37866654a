// Conditions set on single pore cells of the current mesh (YADE's setCellPImposed, blockCell).
// They name cells by index, so they hold until the next remesh, like the indices themselves.
//
// A cell's pressure either follows the boundary conditions (a pressure wall or an imposed
// point makes it a Dirichlet cell, else it is an unknown), or is imposed at the value the cell
// holds (set with FlowEngine::set_cell_pressure), or is free (an unknown even where a boundary
// would impose it). A blocked cell is cut out of the flow problem: every throat it has carries
// no flux, and its pressure stays as it is (zero when blocked with its pressure imposed).
#pragma once
#include <cstdint>
#include <vector>

namespace pfv {

enum class CellPressure : std::int8_t { kFollowBoundaries = 0, kImposed = 1, kFree = 2 };

struct CellConditions {
  std::vector<CellPressure> pressure;  // per cell; empty while no cell has a condition
  std::vector<std::uint8_t> blocked;   // per cell; empty while no cell is blocked

  bool empty() const { return pressure.empty() && blocked.empty(); }
  CellPressure pressure_of(int cell) const {
    return pressure.empty() ? CellPressure::kFollowBoundaries : pressure[cell];
  }
  bool is_blocked(int cell) const { return !blocked.empty() && blocked[cell] != 0; }
  // Sets the pressure condition of one cell of a mesh of n_cells; returns whether it changed.
  bool set_pressure(int cell, CellPressure p, int n_cells);
  // Blocks one cell of a mesh of n_cells; returns whether it was open.
  bool block(int cell, int n_cells);
  void clear() { *this = CellConditions{}; }
};

}  // namespace pfv
