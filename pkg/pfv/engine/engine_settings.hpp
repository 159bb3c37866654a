// User settings of the flow engine. A C++ caller changes them directly; the next step compares
// them with what the current mesh and linear system were built from and rebuilds what is
// stale (pore_mesh.hpp, linear_system.hpp), so that every caller gets the same rebuilds.
#pragma once
#include "pfv/linalg/cholmod_solver.hpp"
#include "pfv/linalg/pressure_solver.hpp"
#include "pfv/model/conductance.hpp"

namespace pfv {

struct EngineSettings {
  ConductanceModel conductance;
  bool slip_boundary = true;
  // With slip_boundary only: multiply R_h of every throat with one wall vertex by 2^-1/4 and with
  // two or three by 2^-1/2 before its conductance is computed, as YADE 2023.02a does
  // (conductance x 0.71 and x 0.5). Not in the thesis; on by default because it is the closer of
  // the two to Stokes flow on random packings (doc/validation.md section 7). Off: the thesis'
  // formula alone, closer on regular packings.
  bool yade_wall_throat_factor = true;
  // kAuto: the Cholesky factor unless its analysis projects more stored values than fit in
  // max_factor_bytes (linear_system.hpp) or than CHOLMOD's 32-bit indices address, else multigrid.
  SolverKind solver = SolverKind::kAuto;
  // The largest Cholesky factor kAuto accepts, in bytes (8 per stored value: factorised in
  // double); 0: half the memory available (MemAvailable) when the system is built, plus the
  // storage of the factor it replaces. A named kCholesky refuses a larger factor with an error
  // (0: all the memory available), checked at each factorisation; both refuse a factor beyond
  // the 2^31 - 1 values CHOLMOD's 32-bit indices address (FactorLimit::kIndexRange).
  double max_factor_bytes = 0;
  // Multigrid (named or chosen by kAuto): the V-cycle's smoother. Jacobi costs less per step
  // where the start stays exact for many steps (a fixed skeleton), Gauss-Seidel where it is
  // close but not exact; the split Gauss-Seidel sweeps make an iteration cheaper than the
  // symmetric pair for a few more iterations (doc/solvers.md). A change rebuilds the hierarchy.
  MultigridSmoother multigrid_smoother = MultigridSmoother::kGaussSeidel;
  double tolerance = 1e-6;  // Gauss-Seidel, incomplete-Cholesky CG
  double relax = 1.9;       // Gauss-Seidel
  int max_iterations = 200000;
  bool force_metis = false;  // YADE's forceMetis: METIS ordering whatever 'ordering' says
  Ordering ordering = Ordering::kAuto;
  // Carry the elimination order over to the next remesh (ordering_reuse.hpp) while its factor
  // has at most max_fill_growth times the entries per unknown of the last fresh ordering.
  bool reuse_ordering = true;
  double max_fill_growth = 1.1;
  // Cholesky only: keep the factor as 32-bit integers scaled per column
  // (FactorPrecision::kScaled32) and refine each solve in double from the previous (extrapolated)
  // pressures (refinement.hpp) until the estimated error is below refinement_tolerance *
  // (max p - min p) over the unknowns. Falls back to the double factor if G is too
  // ill-conditioned for it. Only for factors of at least mixed_precision_min_entries stored
  // entries: a smaller double factor is served from the caches, and the residual of each pass
  // costs what the 32-bit factor saves (doc/solvers.md).
  bool mixed_precision = true;
  double mixed_precision_min_entries = 2e6;
  double refinement_tolerance = 1e-10;
  int max_refinement_passes = 8;
  // Factorise with CHOLMOD's own numeric phase, forking the OpenMP teams compiled into it,
  // instead of PFV's (supernodal_numeric.hpp); kept to measure the difference.
  bool cholmod_openmp_teams = false;
  int mesh_update_interval = 1000;
  double def_tolerance = 0;  // YADE's default: no strain-triggered remesh
  double p_zero = 0;
  // Fluid bulk modulus K (YADE's fluidBulkModulus); 0 = incompressible. When positive each
  // cell stores fluid: (V_f / K) dp/dt enters continuity (implicit Euler), which adds
  // V_f / (K dt) to the diagonal of G; the system is then rebuilt when dt changes.
  double fluid_bulk_modulus = 0;
  // The pore volume a compressible cell stores is at least minimum_porosity times its total
  // volume (YADE's minimumPorosity; cell_queries.hpp), in [0, 1).
  double minimum_porosity = 0;
  // dV/dt of the cells without wall vertices is multiplied by volume_correction (YADE's
  // volumeCorrection, which its desiredPorosity sets at each step), positive.
  double volume_correction = 1;
  // At a remesh, cells whose volume is at most flat_threshold are blocked (YADE's flatThreshold;
  // negative: none). A change applies from the next remesh.
  double flat_threshold = -1;
  // At a remesh, carry the pressures and the blocked cells of the old mesh over to the new cells
  // (located at their power centres) even for an incompressible fluid solved directly (YADE's
  // doInterpolate): the iterative solvers and a compressible fluid always carry them.
  bool interpolate_on_remesh = false;
  // Remesh on a second thread from a snapshot while steps go on with the old mesh (YADE's
  // `multithread`): the new mesh arrives a few steps late.
  bool background_remesh = false;
  // Viscous shear between neighbouring spheres (YADE's viscousShear; viscous_shear.hpp). Off:
  // no pair geometry is built or stored and the step does no extra work.
  bool viscous_shear = false;
  // The viscosity of the shear term when positive (0: viscosity). The thesis (section 6.3.5) adds
  // shear forces at water's 1e-3 Pa s to a seabed whose conductances use a viscosity scaled up
  // with the grain size; YADE has one viscosity for both. Read at every step.
  double shear_viscosity = 0;
  double viscosity_of_shear() const { return shear_viscosity > 0 ? shear_viscosity : conductance.viscosity; }
  // Buoyancy: the engine solves for the excess (piezometric) pressure, so the hydrostatic part of
  // the fluid's action is the force -fluid_density V g on every sphere, added to its fluid force
  // when fluid_density > 0 (thesis 2.17: the buoyant weight). 0: no buoyancy, no cost.
  double fluid_density = 0;
  Vec3 gravity = Vec3::Zero();

  SolveControl solve_control() const {
    return {tolerance, relax, max_iterations, refinement_tolerance, max_refinement_passes};
  }
  // Whether a remesh carries the old mesh's cell states over (see interpolate_on_remesh), for
  // the solver in use: under kAuto the one chosen, which may be iterative.
  bool interpolates(SolverKind in_use) const {
    const bool iterative = in_use != SolverKind::kCholesky && in_use != SolverKind::kAuto;
    return iterative || fluid_bulk_modulus > 0 || interpolate_on_remesh;
  }
  // The ordering CHOLMOD is asked for.
  Ordering factor_ordering() const { return force_metis ? Ordering::kMetis : ordering; }
};

// Throws std::invalid_argument naming the first setting out of its range.
void validate(const EngineSettings& settings);

}  // namespace pfv
