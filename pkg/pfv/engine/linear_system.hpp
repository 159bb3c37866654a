// The linear system of a pore mesh for given boundary conditions: G assembled over the unknown
// cells (pressure_system.hpp) and a solver prepared for it (a factor, a preconditioner). Built
// at every remesh, and again when the boundary conditions, the solver or its settings change;
// like the pore mesh it touches nothing shared.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "pfv/engine/engine_settings.hpp"
#include "pfv/engine/pore_mesh.hpp"
#include "pfv/engine/solver_cost.hpp"
#include "pfv/engine/solver_policy.hpp"
#include "pfv/engine/stage_times.hpp"
#include "pfv/linalg/ordering_reuse.hpp"
#include "pfv/linalg/pressure_solver.hpp"
#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/cell_conditions.hpp"
#include "pfv/model/pressure_rhs.hpp"
#include "pfv/model/pressure_system.hpp"

namespace pfv {

class CholeskySolver;

// The settings and boundary conditions a linear system depends on.
struct SystemRecipe {
  SolverKind solver = SolverKind::kCholesky;
  double viscosity = 0;                 // of the conductances in G
  Ordering ordering = Ordering::kAuto;  // Cholesky only
  bool mixed_precision = false;         // Cholesky only
  double mixed_precision_min_entries = 0;
  // kAuto: a new bound makes the choice again. A named Cholesky reads it at each factorisation
  // only (a held factor is not given up for a lower bound, and a refused one leaves no solver).
  double max_factor_bytes = 0;
  MultigridSmoother multigrid_smoother = MultigridSmoother::kGaussSeidel;  // see reads_multigrid_smoother
  double fluid_bulk_modulus = 0;
  double minimum_porosity = 0;  // enters G only with a compressible fluid
  double dt = 0;                // likewise
  std::array<bool, kWallCount> is_pressure{};
  std::vector<Vec3> imposed_pressure_at, imposed_flux_at;
  PressureProfile profile;

  SystemRecipe() = default;
  SystemRecipe(const EngineSettings& s, const BoundaryConditions& bc, double dt);
  // Whether a system built from this recipe must be rebuilt for these settings, boundary
  // conditions and time step. Boundary values and imposed values are read at every step.
  bool stale_for(const EngineSettings& s, const BoundaryConditions& bc, double dt) const;
};

struct LinearSystem {
  PressureSystem system;
  DirichletCouplings couplings;
  std::unique_ptr<PressureSolver> solver;        // null until built
  std::shared_ptr<const CellOrdering> ordering;  // of a Cholesky factor, for the next remesh
  std::vector<int> imposed_pressure_cells, imposed_flux_cells;
  std::vector<double> storage;  // V_f / (K dt) per cell; empty for an incompressible fluid
  // (cell, pressure) of the Dirichlet cells of bc.profile's wall; empty without a profile.
  std::vector<std::pair<int, double>> profile_pressure;
  FieldCells field;  // of the PressureField's wall, gathered at the first step that needs them
  SystemRecipe recipe;
  // The solver built and why ("multigrid: the Cholesky factor would store ..."), for reports and
  // for the next system's choice under kAuto (solver_policy.hpp).
  SolverDecision decision;
  SolveTally tally;  // the steps this system served, multigrid's iterations
  StageTimes times;  // assembly, analysis, factorization

  bool ready() const { return solver && (system.n_unknowns() == 0 || solver->ready()); }
  // The Cholesky solver, or nullptr with another solver.
  const CholeskySolver* cholesky() const;
  CholeskySolver* cholesky();
};

// What a linear system takes from the engine's state of the mesh's cells: the conditions set
// on single cells, and the stored pore volumes when they were measured again since the remesh
// (empty: from the mesh).
struct CellState {
  const CellConditions* conditions = nullptr;
  const std::vector<double>* void_volume = nullptr;
};

// Throws std::domain_error if the system is singular, std::invalid_argument if an imposed point
// lies in no pore cell, std::runtime_error if a named Cholesky solver's factor exceeds its bound
// (max_factor_bytes, else the memory available) or CHOLMOD's index range. previous: the ordering of the last
// factorisation, tried first when settings.reuse_ordering (null: compute one). recycled: the
// released solver of the previous system, reused (with the storage of its factor's values) if
// it is of the kind the settings ask for (solver_policy.hpp). history: what the solves of the
// earlier systems showed, which kAuto weighs (solver_cost.hpp).
LinearSystem build_linear_system(const PoreMesh& mesh, const BoundaryConditions& bc, const EngineSettings& settings,
                                 double dt, const CellOrdering* previous = nullptr,
                                 std::unique_ptr<PressureSolver> recycled = nullptr, CellState cells = {},
                                 const SolveHistory& history = {});

// The history 'system' leaves after the one it started from: its steps, multigrid's iterations
// per step if it solved them, and the choice kAuto made for it.
SolveHistory history_after(const LinearSystem& system, SolveHistory before);

}  // namespace pfv
