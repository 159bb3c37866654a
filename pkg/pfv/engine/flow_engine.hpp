// The coupled flow engine: one call per DEM step runs the pipeline
//   scene snapshot -> (remesh: pore mesh, linear system) -> dV/dt -> solve -> forces.
// It knows nothing of YADE; pkg/pfv/python adapts it to YADE's FlowEngine interface. What is
// computed from a finished step lives beside it: flow_queries.hpp (fluxes, averages),
// viscous_stability.hpp (the stability limit); the right-hand-side physics is model/'s
// (pressure_rhs.hpp), the remesh schedule and background remesh remesher.hpp's.
#pragma once
#include <functional>
#include <memory>
#include <vector>

#include "pfv/common/parallel.hpp"
#include "pfv/engine/engine_settings.hpp"
#include "pfv/engine/linear_system.hpp"
#include "pfv/engine/pore_mesh.hpp"
#include "pfv/engine/remesher.hpp"
#include "pfv/engine/stage_times.hpp"
#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/cell_conditions.hpp"

namespace pfv {

class FlowEngine {
 public:
  // Changed freely between steps; the next step rebuilds whatever they make stale.
  EngineSettings settings;
  BoundaryConditions bc;
  // Evaluated once per step (boundary_conditions.hpp); its values enter the right-hand side only.
  PressureField pressure_field;
  // Called once for every new mesh, whichever way it came (remesh(), a step's own remesh, one
  // adopted from the background, one forced by inverted cells), once the mesh is adopted and before
  // its linear system is built: the place for conditions on the new cells (YADE's blockHook), so
  // that they hold on every mesh from its first step. It may read the engine and set conditions on
  // single cells; step(), remesh(), resume() and release() refuse to run inside it. A hook that
  // throws fails the step.
  std::function<void()> mesh_hook;

  FlowEngine() = default;
  FlowEngine(FlowEngine&&) = default;
  FlowEngine& operator=(FlowEngine&&) = default;

  // One coupled step at positions X(t); dt is the DEM step that led here.
  // Throws std::invalid_argument on bad positions or settings, std::domain_error on a singular
  // system or non-finite results; the engine is unchanged by a step that throws (its mesh, system,
  // results, history, schedule and counts: see retract_step), but for a Cholesky factor that a
  // failed remesh had released (the next step factorises again) and a background remesh in flight.
  void step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls, double dt);
  // Undoes the last step (or remesh()) as if it had thrown: for a caller whose own part of the step
  // failed after the engine's (the forces never reached the bodies). Possible until accept_step()
  // or the next step or remesh(); edits of single cells made since are undone with it. Returns
  // whether there was a step to undo.
  bool retract_step();
  // The last step stands: what retract_step() would need (the mesh a remesh replaced) is freed.
  void accept_step();
  // Grows with every mesh adopted and never repeats (a retracted remesh does not give its number
  // back): the key of what callers keep per mesh.
  long mesh_id() const { return mesh_id_; }

  // Remeshes now at these positions (in the foreground) without building the linear system:
  // the next step builds it, with the conditions set on the new cells meanwhile (YADE's blockHook
  // runs in between). Throws as step() does for bad positions or settings.
  void remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls);
  // The next step remeshes (in the foreground).
  void request_remesh() { remesher_.request(); }
  // The next step rebuilds the linear system (YADE's updateBCs; changes of the boundary types,
  // imposed points and solver settings are noticed without it).
  void request_system_rebuild() { system_rebuild_requested_ = true; }
  // Forget the previous positions: the next step has no dV/dt term. For when the boundary
  // is redefined (a moved fictitious wall is not a change of pore volume).
  void reset_history() { has_prev_ = false; }
  // Free the mesh, the system and every per-cell result (keeping the settings and boundary
  // conditions): for an engine taken out of use. A later step starts afresh with a remesh.
  void release();

  // What a run needs to go on exactly where it stopped (a saved and reloaded simulation): the
  // positions the current mesh was built from, the positions of the last step, the pressures,
  // the conditions set on single cells, and the remesh schedule. resume() rebuilds the same mesh
  // (the triangulation is a function of its input) and restores the rest, so that the next step
  // equals the uninterrupted run's; the cell indices of the rebuilt mesh are those of the saved.
  struct RunState {
    MeshSource mesh;
    std::vector<Vec3> previous_centres;  // empty: no dV/dt history
    BoxWalls previous_walls;
    std::vector<double> pressure;     // per cell of the mesh
    CellConditions cells;             // set on single cells of the mesh (set_cell_imposed, block_cell)
    std::vector<double> void_volume;  // measured by initialize_volumes (empty: the mesh's own)
    int steps_since_remesh = 0;
    double strain = 0;
  };
  RunState run_state() const;  // needs a mesh
  // Throws std::invalid_argument (as a step would) for a state whose positions are invalid, or
  // whose pressures do not match the rebuilt mesh; the engine is then left without a mesh.
  void resume(const RunState& state, double dt);
  bool remesh_due() const { return remesher_.due(settings, mesh_.get()); }
  // The remesh schedule (steps and strain since the last remesh) and a background remesh in flight.
  const Remesher& remesher() const { return remesher_; }
  bool has_mesh() const { return mesh_ != nullptr; }

  // Conditions on single cells of the current mesh (YADE's setCellPImposed, setCellPressure,
  // blockCell; cell_conditions.hpp). A remesh clears them, as it renumbers the cells. A change
  // rebuilds the linear system at the next step; cells are checked by the caller.
  // imposed: the cell's pressure is imposed at the value it holds (else it is an unknown even
  // where a boundary would impose it).
  void set_cell_imposed(int cell, bool imposed);
  // The pressure the cell holds: the value an imposed cell keeps, the state a compressible
  // cell starts the next step from; an unknown of an incompressible fluid is solved anew.
  // Throws std::invalid_argument if p is not finite.
  void set_cell_pressure(int cell, double p);
  // Cuts the cell out of the flow problem (no flux through its throats); its pressure stays
  // as it is, or is set to zero and counted as imposed with zero_pressure.
  void block_cell(int cell, bool zero_pressure);
  const CellConditions& cell_conditions() const { return cells_; }
  // The pore volume each cell stores (V_f floored at minimum_porosity V; cell_queries.hpp): of
  // the mesh, or as measured by the last initialize_volumes since the remesh.
  std::vector<double> void_volumes() const;
  // YADE's initializeVolumes: the stored pore volumes are measured again at these positions
  // (the sphere sectors of the mesh kept), and the next step starts without a dV/dt term.
  void initialize_volumes(const std::vector<Vec3>& centres, const BoxWalls& walls);
  // YADE's updateVolumes: the volume rates become those from the last step's positions to
  // these, which become the reference of the next step's dV/dt. Throws std::invalid_argument
  // for positions of another number of spheres, or a dt that is not positive.
  void update_volumes(const std::vector<Vec3>& centres, const BoxWalls& walls, double dt);

  // Results of the last step.
  const std::vector<Vec3>& forces() const { return force_; }  // spheres, then six walls
  // The viscous shear part of forces() (empty while viscous_shear is off; zero on a step
  // without previous positions, whose velocities are unknown).
  const std::vector<Vec3>& shear_forces() const { return shear_force_; }
  // The pairs of the current mesh, or nullptr while viscous_shear is off.
  const ViscousShear* viscous_shear() const { return mesh_ && mesh_->shear ? &*mesh_->shear : nullptr; }
  const std::vector<double>& pressure() const { return pressure_; }
  const std::vector<double>& volume_rates() const { return volume_rate_; }  // dV/dt per cell
  // The current mesh, with its geometry, conductances and force cache (needs a mesh).
  const PoreMesh& pore_mesh() const { return *mesh_; }
  const Mesh& mesh() const { return mesh_->mesh(); }
  const CellGeometry& cells() const { return mesh_->cells; }
  const FacetGeometry& facets() const { return mesh_->facets; }
  const std::vector<double>& conductances() const { return mesh_->k; }
  const PressureSystem& system() const { return linear_.system; }
  // The current linear system with its solver and the cells of the boundary conditions.
  const LinearSystem& linear_system() const { return linear_; }
  const BoxWalls& walls() const { return walls_prev_; }
  // The sphere centres of the last step (of the last update_volumes, if later; empty before the first): the
  // positions of walls() and pressure().
  const std::vector<Vec3>& positions() const { return centres_prev_; }
  // The Cholesky factor of the current system; throws std::logic_error with another solver.
  const CholmodSolver& cholmod() const;
  // The current system's Cholesky solver, or nullptr (another solver, or no system yet).
  const CholeskySolver* cholesky() const { return linear_.cholesky(); }
  // The current system's solver, null before the first step.
  const PressureSolver* pressure_solver() const { return linear_.solver.get(); }
  int remesh_count() const { return remesh_count_; }
  // Remeshes forced because the spheres had turned 2 % of the meshed volume inside out since
  // the last remesh (motion too large for the remesh schedule); each also counts in remesh_count().
  int inversion_remeshes() const { return inversion_remeshes_; }
  // Cells inside out at the last step's positions (a flipped volume above a small part of the
  // mean), and the part of the meshed volume they hold. Up to 2 % of the volume the step runs
  // on with signed volumes until the scheduled remesh; beyond, it remeshes at once.
  int inverted_cells() const { return inverted_cells_; }
  double inverted_volume_fraction() const { return meshed_volume_ > 0 ? inverted_volume_ / meshed_volume_ : 0.0; }
  // Linear systems adopted so far: one per remesh, plus one per rebuild without a remesh.
  int system_builds() const { return system_builds_; }
  // Steps that evaluated the pressure_field so far.
  int field_evaluations() const { return field_evaluations_; }
  const SolveStats& last_solve() const { return last_solve_; }
  // The right-hand side and the solution of the last solve, one value per unknown of system().
  const std::vector<double>& last_rhs() const { return rhs_; }
  const std::vector<double>& last_solution() const { return solution_; }
  const StageTimes& remesh_times() const { return remesh_times_; }
  const StageTimes& step_times() const { return step_times_; }

 private:
  // What a step may replace before it commits, and what its commit replaced (retract_step). The
  // large objects are moved here, not copied, only when the step replaces them.
  struct Undo {
    bool open = false;        // a step (or remesh()) began and was neither accepted nor undone
    bool committed = false;   // its commit() ran
    bool trend_kept = false;  // commit() kept the pressures before it for the extrapolated start
    // The state of the mesh the step replaced (adopt), when it did.
    bool mesh_replaced = false;
    std::unique_ptr<PoreMesh> mesh;
    CellConditions cells;
    std::vector<double> pressure, pressure_before, volume, volume_rate, measured_void_volume;
    // The linear system the step replaced (adopt, rebuild_stale_system), when it did.
    bool system_replaced = false;
    LinearSystem linear;
    // Taken at the start: the counts, flags and schedule; solve()'s count in the system's tally.
    int tallied_iterations = -1;  // none
    SolveHistory history;
    SolveStats last_solve;
    Remesher::Schedule schedule;
    long launches = 0;                // the remesher's background remeshes
    bool adopted_background = false;  // the step adopted a mesh built in the background
    bool has_prev = false, pressures_solved = false, keep_trend = false, rebuild_requested = false;
    int remesh_count = 0, inversion_remeshes = 0, system_builds = 0, field_evaluations = 0, inverted_cells = 0;
    double inverted_volume = 0, meshed_volume = 0;
    // What commit() replaced: the pressures before the extrapolation's (when not kept), the positions and walls.
    std::vector<double> committed_pressure_before;
    std::vector<Vec3> centres;  // keeps its capacity from step to step (reset())
    BoxWalls walls;

    // Frees what it holds, keeping the capacity of the positions' buffer.
    void reset();
  };
  // flow_engine_undo.cpp: the start of a step or remesh(); moving the replaced mesh or system aside.
  void begin_undo();
  void retire_mesh();
  void retire_system();
  // Refuses step(), remesh(), resume() and release() inside mesh_hook.
  void refuse_inside_hook(const char* what) const;
  // Adopts the mesh, runs mesh_hook, and builds the mesh's system after it (with_system: the
  // system is built now, recycling the given solver; else at the next step).
  void adopt_and_hook(Remesh&& r, std::unique_ptr<PressureSolver> recycled, double dt, bool with_system);
  void run_mesh_hook();

  // The stages of step(), in order.
  void validate_step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                     double dt) const;
  void schedule_remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                       double dt);
  void rebuild_stale_system(double dt);
  double assemble(const std::vector<Vec3>& centres, const BoxWalls& walls, double dt);  // returns the pore strain
  void assemble_rhs();  // once per step, on the mesh the step solves on (pressure_rhs.hpp)
  void solve(double dt);
  void compute_forces(const std::vector<Vec3>& centres, const std::vector<double>& radii, double dt);
  void commit(const std::vector<Vec3>& centres, const BoxWalls& walls, double strain);

  // The volume of every cell at these positions; throws std::invalid_argument if they do not
  // belong to the mesh's spheres.
  std::vector<double> volumes_at(const std::vector<Vec3>& centres, const BoxWalls& walls) const;

  // Adopting a new mesh (flow_engine_remesh.cpp).
  void adopt_finished_remesh();
  void remesh_now(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls, double dt);
  // The first half of a foreground remesh: a background remesh in flight is superseded, the mesh
  // of these positions is built, with its flat cells and the blocked cells carried over.
  Remesh mesh_without_system(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls);
  // with_system: the linear system of the mesh (else an empty one, built at the next step).
  void adopt(PoreMesh&& mesh, LinearSystem&& linear, CellConditions&& conditions, bool with_system = true);
  // With settings.interpolates(solver in use), blocks the cells of the new mesh whose barycentres (at these
  // positions) lie in a blocked cell of the current one; returns whether it blocked any.
  bool carry_blocked_cells(const PoreMesh& mesh, CellConditions& conditions, const std::vector<Vec3>& centres,
                           const BoxWalls& walls) const;
  // The current system's solver with its factor freed, handed over to the next build (the
  // storage of the factor's values is reused): peak memory one factor, no new pages to fault.
  std::unique_ptr<PressureSolver> released_solver();
  // Under kAuto: multigrid was chosen for the current system and the bound it was chosen against
  // is unchanged, so the next system keeps it without an analysis (build_linear_system).
  bool auto_keeps_multigrid() const;

  std::unique_ptr<PoreMesh> mesh_;
  LinearSystem linear_;
  SolveHistory solve_history_;  // of the systems before linear_ (solver = auto weighs it)
  Remesher remesher_;

  std::vector<double> pressure_, volume_, volume_rate_, rhs_, solution_;
  std::vector<Vec3> force_;
  std::vector<double> next_volume_, next_pressure_, next_volume_rate_;  // scratch of the step being computed
  std::vector<double> field_values_;                                    // scratch of the pressure field
  std::vector<double> pressure_before_;  // the step before pressure_'s, on this mesh (extrapolated start)
  bool keep_trend_ = false;              // the solver of this step wants the extrapolated start next
  bool pressures_solved_ = false;        // pressure_ solved on this mesh (or carried over), not pZero
  std::vector<Vec3> next_force_;
  std::vector<Vec3> shear_force_, next_shear_;  // only with viscous_shear
  std::vector<Vec3> centres_prev_;
  BoxWalls walls_prev_;
  bool has_prev_ = false;
  int remesh_count_ = 0;
  int inverted_cells_ = 0;                          // of the last assemble()
  double inverted_volume_ = 0, meshed_volume_ = 0;  // likewise: |volume| of those cells, and of all
  int inversion_remeshes_ = 0;
  int system_builds_ = 0;
  int field_evaluations_ = 0;
  SolveStats last_solve_;
  CellConditions cells_;                      // of the current mesh
  std::vector<double> measured_void_volume_;  // of the current mesh, by initialize_volumes (else empty)
  bool system_rebuild_requested_ = false;
  StageTimes remesh_times_, step_times_;
  long mesh_id_ = 0;
  // One thread or the team for the loops of dV/dt and of the forces, by their measured times.
  LoopChoice volume_loop_, force_loop_;
  bool in_hook_ = false;  // mesh_hook is running
  Undo undo_;
};

}  // namespace pfv
