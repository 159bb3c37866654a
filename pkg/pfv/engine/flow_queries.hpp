// What a caller asks of an engine after a step (YADE's getBoundaryFlux, averagePressure,
// averageSlicePressure, ...): read from its state, on demand, never by the step. The flux
// balances themselves are model/'s (flow_totals.hpp).
#pragma once
#include <string>

#include "pfv/engine/flow_engine.hpp"

namespace pfv {

// Fluid leaving through the wall in the last step (flow_totals.hpp).
double boundary_flux(const FlowEngine& engine, int wall);
// The imposed fluxes that entered the last step's system.
double imposed_flux_total(const FlowEngine& engine);
// The sum of dV/dt over all cells.
double volume_rate_total(const FlowEngine& engine);
// The pressure averaged over the cells weighted by their volumes (0 without a mesh).
double average_pressure(const FlowEngine& engine);
// The pressure averaged over the slice at this position along axis (0, 1 or 2), sampled on a
// regular grid of the wall-bounded section. Throws std::invalid_argument for another axis, or
// a slice that lies outside the pore mesh.
double average_slice_pressure(const FlowEngine& engine, int axis, double position);
// Whether the cell's pressure is imposed: by its own condition, else by a pressure wall or an
// imposed point of the current boundary conditions (a blocked cell: blocked with its pressure).
bool cell_imposed(const FlowEngine& engine, int cell);
// The cell holding the point x, or -1 (outside the pore space, or no mesh).
int locate(const FlowEngine& engine, const Vec3& x);

// Of the current system's solver: whether its Cholesky factor was ordered by METIS; the
// refinement contraction (-1 until measured, or without a 32-bit factor); which solver it is and
// why (LinearSystem::choice; empty before the first system); the assembly, analysis and
// factorisation times of the system.
bool metis_used(const FlowEngine& engine);
double refinement_contraction(const FlowEngine& engine);
const std::string& solver_choice(const FlowEngine& engine);
const StageTimes& system_times(const FlowEngine& engine);

// The viscosity of the current mesh's conductances: settings.conductance.viscosity once a step
// has run since it changed.
double mesh_viscosity(const FlowEngine& engine);

}  // namespace pfv
