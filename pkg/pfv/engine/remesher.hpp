// When the engine remeshes, and the remesh built on another thread meanwhile. The schedule
// (steps and pore strain since the last remesh, a remesh asked for) says when a new mesh is due;
// a background remesh snapshots the positions, builds the pore mesh and its linear system on a
// worker (which touches nothing shared), and hands them over once finished. Adopting a new mesh
// into the engine's state is the engine's (flow_engine_remesh.cpp).
#pragma once
#include <future>
#include <memory>
#include <optional>
#include <vector>

#include "pfv/engine/engine_settings.hpp"
#include "pfv/engine/linear_system.hpp"
#include "pfv/engine/pore_mesh.hpp"
#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/cell_conditions.hpp"

namespace pfv {

// A pore mesh with what a remesh builds for it.
struct Remesh {
  PoreMesh mesh;
  LinearSystem linear;   // empty when the next step builds it
  CellConditions cells;  // those of the new mesh: its flat cells
};

// The conditions of a new mesh: its cells of at most settings.flat_threshold volume blocked.
CellConditions flat_cells(const PoreMesh& mesh, const EngineSettings& settings);

class Remesher {
 public:
  Remesher() = default;
  Remesher(Remesher&&) = default;
  Remesher& operator=(Remesher&&) = default;
  ~Remesher();  // a remesh in flight is waited for: the worker reads copies only, but let it finish

  // Whether the next step remeshes: asked for, no mesh yet, or the schedule's interval or pore
  // strain reached, or settings the mesh depends on changed.
  bool due(const EngineSettings& settings, const PoreMesh* mesh) const;
  // The next step remeshes (in the foreground).
  void request() { requested_ = true; }
  bool requested() const { return requested_; }
  // A mesh (and its system) is being built in the background.
  bool pending() const { return pending_.has_value(); }
  // Background remeshes started so far.
  long launches() const { return launches_; }
  // Blocks until a background remesh in flight has finished; the next step adopts it.
  void wait() const;
  // A background remesh in flight is superseded: waited for and dropped.
  void cancel();
  // Snapshot these positions and settings and build their mesh and linear system on another
  // thread; the schedule starts again. ordering: the current factor's (tried first);
  // keep_multigrid: the current system's multigrid choice stands under kAuto (auto_keeps_multigrid);
  // history: what the solves so far showed (build_linear_system).
  void remesh_in_background(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                            const EngineSettings& settings, const BoundaryConditions& bc, double dt,
                            std::shared_ptr<const CellOrdering> ordering, bool keep_multigrid,
                            const SolveHistory& history);
  // The background remesh once it has finished, else nothing. Rethrows what the worker threw,
  // after asking the next step to remesh in the foreground (which then says why).
  std::optional<Remesh> take_finished();

  // A remesh was adopted: the schedule starts again.
  void restart();
  // A step on the current mesh succeeded with this pore strain.
  void count_step(double strain) {
    strain_ += strain;
    ++steps_since_remesh_;
  }
  int steps_since_remesh() const { return steps_since_remesh_; }
  double strain() const { return strain_; }
  // The schedule of a saved run (FlowEngine::resume).
  void restore(int steps_since_remesh, double strain);
  // The whole schedule, for a step that may be undone (FlowEngine::retract_step).
  struct Schedule {
    double strain = 0;
    int steps_since_remesh = 0;
    bool requested = false;
  };
  Schedule schedule() const { return {strain_, steps_since_remesh_, requested_}; }
  void set_schedule(const Schedule& s) {
    strain_ = s.strain;
    steps_since_remesh_ = s.steps_since_remesh;
    requested_ = s.requested;
  }
  // Drops any remesh in flight and asks for a new mesh (FlowEngine::release).
  void reset();

 private:
  struct Pending {
    std::future<Remesh> result;
  };
  std::optional<Pending> pending_;
  long launches_ = 0;
  double strain_ = 0;
  int steps_since_remesh_ = 0;
  bool requested_ = true;
};

}  // namespace pfv
