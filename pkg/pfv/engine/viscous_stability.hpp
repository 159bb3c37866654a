// The stability limit of the explicit fluid-DEM coupling from the fluid alone, and certified
// lower bounds on it, over an engine that has run a step (read only): linearised about the last
// step's positions on the current mesh and system.
#pragma once
#include <vector>

#include "pfv/engine/flow_engine.hpp"

namespace pfv {

// Stability limit of the explicit coupling from the fluid alone: 2 / lambda_max of
// M^-1 V, where V maps sphere velocities to fluid forces through the current mesh
// (dV/dt -> solve -> forces, plus the viscous shear term when on), linearised about the
// last step's positions; masses <= 0 mark spheres that do not move. Collective modes
// (groups of spheres squeezing shared pores) make this smaller than the thesis'
// single-particle dt_MV. Needs a mesh (viscous_stability.cpp).
// Without a mode: Arnoldi from a fixed start, at most 'iterations' operator applications,
// stopping once the largest Ritz value changes by less than 1e-6 or its residual is below
// 1e-3 of it (at least 8 applications). mode: if given with one
// entry per sphere (not all zero), power iteration starts from it instead (warm start from
// the previous mesh's mode, stopping once the estimate changes by less than 0.5 %). On
// return mode holds the estimated eigenvector (unit norm), and applications (if given) the
// number of operator applications made. Throws std::domain_error if the operator gives a
// non-finite estimate.
double viscous_stability_limit(const FlowEngine& engine, const std::vector<double>& mass, int iterations,
                               std::vector<Vec3>* mode = nullptr, int* applications = nullptr);
// Certified lower bounds on viscous_stability_limit (viscous_stability_bounds.cpp), 0 where
// there is none (viscous shear on, or the pressure matrix not of the form the argument needs).
// The global bound costs about one solve and lies up to four orders of magnitude below the
// limit, the further the longer the drainage path; the local bound solves only small problems
// around each sphere, costs more at these sizes, and lies within an order of magnitude.
double viscous_stability_bound(const FlowEngine& engine, const std::vector<double>& mass);
double viscous_stability_local_bound(const FlowEngine& engine, const std::vector<double>& mass);
// accel = M^-1 F(v): the fluid forces of the sphere velocities v on the current mesh over
// the masses (zero for mass <= 0). The operator of viscous_stability_limit; public for tests.
void apply_viscous_operator(const FlowEngine& engine, const std::vector<double>& mass, const std::vector<Vec3>& v,
                            std::vector<Vec3>& accel);

// Throws unless there is a mesh and one finite mass per sphere of it (the limit and its bounds).
void check_stability_inputs(const FlowEngine& engine, const std::vector<double>& mass);
// The displacement by which the limit and its bounds difference cell volumes: a tiny fraction
// of the box, the same for all of them so that they differentiate alike.
double volume_probe_step(const FlowEngine& engine);

}  // namespace pfv
