// The linear system G p = -dV/dt + Q_q + Q_p over the pore cells (thesis 3.5).
//
// Cells touching a pressure wall, or holding an imposed pressure, are Dirichlet cells and
// drop out of the unknowns; their pressures enter the right-hand side. Conditions set on single
// cells (cell_conditions.hpp) impose or free a cell's pressure, or block the cell: a blocked
// cell is no unknown and its throats carry no flux. G is symmetric positive definite once every
// group of connected unknown cells reaches a Dirichlet cell; assembly checks this and names the
// problem otherwise.
#pragma once
#include <memory>
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"
#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/boundary_source.hpp"
#include "pfv/model/cell_conditions.hpp"
#include "triangulation/mesh.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct PressureSystem {
  // Per cell.
  std::vector<int> unknown;            // index among unknowns, -1 for any other cell
  std::vector<BoundarySource> source;  // where its pressure comes from (boundary_source.hpp)
  std::vector<double> diagonal;        // sum of k over the cell's throats
  // Cell adjacency through throats, both directions (CSR); k is 0 through a blocked cell's throats.
  std::vector<int> adj_start, adj_cell;
  std::vector<double> adj_k;
  // Unknowns.
  std::vector<int> unknown_cell;
  // G over the unknowns, unknown u's row and column u; shared with the solver set up for it
  // (PressureSolver::setup), which keeps it for its solves.
  std::shared_ptr<const SymmetricMatrix> matrix = std::make_shared<const SymmetricMatrix>();

  int n_unknowns() const { return static_cast<int>(unknown_cell.size()); }
};

// imposed_cells[k] is the cell of bc.imposed_pressure[k] (-1 if it lies in no cell).
// storage (optional, per cell) adds V_i / (K dt) to the diagonal: fluid compressibility.
// cells (optional): the conditions set on single cells, which override the boundaries.
PressureSystem assemble_pressure_system(const Mesh& mesh, const FacetGeometry& facets, const std::vector<double>& k,
                                        const BoundaryConditions& bc, const std::vector<int>& imposed_cells,
                                        const std::vector<double>& storage = {}, const CellConditions& cells = {});

// Pressures of the Dirichlet cells of walls and imposed points from the current boundary values
// (cheap; every step). Cells imposed on themselves and blocked cells keep their pressures.
void apply_dirichlet_values(const PressureSystem& s, const BoundaryConditions& bc, std::vector<double>& pressure);

}  // namespace pfv
