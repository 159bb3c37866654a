// The right-hand side of one step's pressure system, b = -dV/dt + Q_q + Q_p (thesis 3.5), beside
// the matrix G of pressure_system.hpp: the pressures of the Dirichlet cells this step (boundary
// values, a time-dependent PressureField) and the vector b over the unknowns. Cheap and done at
// every step; nothing here changes G, so a time-dependent load never costs a new factor.
#pragma once
#include <vector>

#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/pressure_system.hpp"

namespace pfv {

// The throats from unknown cells to Dirichlet cells (imposed pressures): the entries of G that
// move into b. None through a blocked cell.
struct DirichletCouplings {
  std::vector<int> unknown, cell;
  std::vector<double> k;
};
DirichletCouplings dirichlet_couplings(const PressureSystem& system);

// The Dirichlet cells of a PressureField's wall and their power centres: gathered at the first
// step that needs them, then kept with the system they belong to (wall: theirs, -1 before).
struct FieldCells {
  int wall = -1;
  std::vector<int> cells;
  std::vector<Vec3> at;
};

// Evaluates the field at the power centres of its wall's Dirichlet cells and writes their
// pressures. Returns false without evaluating if the field is inactive or its wall has no
// Dirichlet cell (not a pressure wall, or each of its cells freed or blocked). values: scratch.
// Throws std::invalid_argument if the field gives another number of values or a non-finite one.
bool apply_pressure_field(const PressureField& field, const PressureSystem& system,
                          const std::vector<Vec3>& power_centre, FieldCells& cells, std::vector<double>& values,
                          std::vector<double>& pressure);

// The terms of b other than the Dirichlet pressures, all per cell unless said otherwise.
struct RhsTerms {
  const std::vector<double>& volume_rate;      // dV/dt
  const std::vector<double>& storage;          // V_f / (K dt); empty for an incompressible fluid
  const std::vector<double>& pressure;         // p^n, the stored fluid's state (read with storage only)
  const std::vector<int>& imposed_flux_cells;  // the cell of each imposed flux (-1: none)
  const std::vector<PointCondition>& imposed_flux;
  const DirichletCouplings& couplings;
};

// b = -dV/dt (+ V_f/(K dt) p^n, implicit Euler on the stored fluid) + the imposed fluxes into
// unknown cells + the couplings to the Dirichlet cells at their pressures of this step
// (boundary_pressure, per cell). One value per unknown in rhs.
void assemble_rhs(const PressureSystem& system, const RhsTerms& terms, const std::vector<double>& boundary_pressure,
                  std::vector<double>& rhs);

}  // namespace pfv
