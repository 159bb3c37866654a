// Seconds spent in each stage of the pipeline: by the last remesh, and by the last step.
#pragma once

namespace pfv {

struct StageTimes {
  double triangulation = 0, geometry = 0, conductance = 0, assembly = 0, analysis = 0, factorization = 0;
  double force_cache = 0, volumes = 0, solve = 0, forces = 0;
  double shear_geometry = 0, shear_forces = 0;  // zero while viscous_shear is off
  double pressure_field = 0;                    // the call of FlowEngine::pressure_field (zero without)
  double carry_over = 0;  // remesh: the old pressures located at the new cells (zero unless interpolating)
  double total = 0;       // the whole FlowEngine::step (step_times only), remesh included if it remeshed
};

}  // namespace pfv
