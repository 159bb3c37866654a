// Totals and averages of a solved step over the pore space (YADE's getBoundaryFlux,
// averagePressure, ...): computed on demand from the system, the pressures and the volume
// rates, never by the step.
#pragma once
#include <vector>

#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/pressure_system.hpp"

namespace pfv {

// Fluid leaving through the wall: what flows into its Dirichlet cells from the rest of the
// pore space, plus what those cells expel themselves as they shrink (a moving drained wall
// sweeps their volume). Without deformation only the first term remains.
double boundary_flux(const PressureSystem& system, const std::vector<double>& pressure,
                     const std::vector<double>& volume_rate, int wall);

// The imposed fluxes that enter the system: those whose cell is an unknown (imposed_flux_cells:
// the cell of each, -1 for none).
double imposed_flux_total(const PressureSystem& system, const std::vector<int>& imposed_flux_cells,
                          const std::vector<PointCondition>& imposed_flux);

// The sum of dV/dt over all cells.
double volume_rate_total(const std::vector<double>& volume_rate);

// The pressure averaged over the cells weighted by their volumes (0 without cells).
double average_pressure(const std::vector<double>& pressure, const std::vector<double>& volume);

}  // namespace pfv
