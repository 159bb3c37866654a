// User settings of the flow engine, and the per-stage timings it reports.
#pragma once
#include "cholmod_solver.hpp"
#include "conductance.hpp"

namespace pfv {

struct EngineSettings {
  ConductanceModel conductance;
  bool slip_boundary = true;
  int use_solver = 3;  // 0 Gauss-Seidel, 1 preconditioned CG (PFV), 3 CHOLMOD
  double tolerance = 1e-6;
  double relax = 1.9;
  int max_gs_iterations = 200000;
  bool force_metis = false;  // YADE's forceMetis: METIS ordering whatever 'ordering' says
  Ordering ordering = Ordering::kAuto;
  // Carry the elimination order over to the next remesh (ordering_reuse.hpp) while its factor
  // has at most max_fill_growth times the entries per unknown of the last fresh ordering.
  bool reuse_ordering = true;
  double max_fill_growth = 1.1;
  // useSolver 3 only: keep the Cholesky factor as 32-bit integers scaled per column
  // (FactorPrecision::kScaled32) and refine each solve in double from the previous (extrapolated)
  // pressures (refinement.hpp) until the estimated error is below refinement_tolerance *
  // (max p - min p) over the unknowns. Falls back to the double factor if G is too
  // ill-conditioned for it. Only for factors of at least mixed_precision_min_entries stored
  // entries: a smaller double factor is served from the caches, and the residual of each pass
  // costs what the 32-bit factor saves (bench/mixed_precision_dem.py: parity at 3 000 spheres,
  // whose factor holds 1.7e6 entries; 20 % faster at 50 000; doc/benchmarks.md).
  bool mixed_precision = true;
  double mixed_precision_min_entries = 2e6;
  double refinement_tolerance = 1e-10;
  int max_refinement_passes = 8;
  // Let CHOLMOD fork the OpenMP teams of its numeric factorisation (4 threads, compiled in)
  // instead of running them on the calling thread (serial_openmp.hpp); kept to measure the
  // difference (bench/solver_stages.py).
  bool cholmod_openmp_teams = false;
  int mesh_update_interval = 1000;
  double def_tolerance = 0;  // YADE's default: no strain-triggered remesh
  double p_zero = 0;
  // Fluid bulk modulus K (YADE's fluidBulkModulus); 0 = incompressible. When positive each
  // cell stores fluid: (V_f / K) dp/dt enters continuity (implicit Euler), which adds
  // V_f / (K dt) to the diagonal of G; the system is then refactorised when dt changes.
  double fluid_bulk_modulus = 0;
  // Remesh on a second thread from a snapshot while steps go on with the old mesh (YADE's
  // `multithread`): the new mesh arrives a few steps late.
  bool background_remesh = false;
  // Viscous shear between neighbouring spheres (YADE's viscousShear; viscous_shear.hpp). Off:
  // no pair geometry is built or stored and the step does no extra work.
  bool viscous_shear = false;
};

// Seconds spent in each stage: the last remesh, and the last step without remesh.
struct StageTimes {
  double triangulation = 0, geometry = 0, conductance = 0, assembly = 0, analysis = 0, factorization = 0;
  double force_cache = 0, volumes = 0, solve = 0, forces = 0;
  double shear_geometry = 0, shear_forces = 0;  // zero while viscous_shear is off
};

}  // namespace pfv
