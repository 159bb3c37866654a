// The coupled flow engine: one call per DEM step runs the pipeline
//   scene snapshot -> (remesh: triangulation -> pore geometry -> conductances -> system ->
//   factorisation -> force cache) -> dV/dt -> solve -> forces.
// It knows nothing of YADE; pkg/pfv/python adapts it to YADE's FlowEngine interface.
#pragma once
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "boundary_conditions.hpp"
#include "cholmod_solver.hpp"
#include "conductance.hpp"
#include "force_cache.hpp"
#include "pore_geometry.hpp"
#include "pressure_system.hpp"
#include "regular_triangulation.hpp"

namespace pfv {

struct EngineSettings {
  ConductanceModel conductance;
  bool slip_boundary = true;
  int use_solver = 3;  // 0 Gauss-Seidel, 3 CHOLMOD
  double tolerance = 1e-6;
  double relax = 1.9;
  int max_gs_iterations = 200000;
  bool force_metis = false;  // YADE's forceMetis: METIS ordering whatever 'ordering' says
  Ordering ordering = Ordering::kAuto;
  int mesh_update_interval = 1000;
  double def_tolerance = 0;  // YADE's default: no strain-triggered remesh
  double p_zero = 0;
};

// Seconds spent in each stage: the last remesh, and the last step without remesh.
struct StageTimes {
  double triangulation = 0, geometry = 0, conductance = 0, assembly = 0, analysis = 0, factorization = 0;
  double force_cache = 0, volumes = 0, solve = 0, forces = 0;
};

class FlowEngine {
 public:
  EngineSettings settings;
  BoundaryConditions bc;

  // One coupled step at positions X(t); dt is the DEM step that led here.
  // Throws std::invalid_argument on bad positions, std::domain_error on a singular system;
  // the engine is unchanged by a step that throws.
  void step(const std::vector<Vec3>& centres, const std::vector<double>& radii,
            const BoxWalls& walls, double dt);

  void request_remesh() { remesh_requested_ = true; }
  // Forget the previous positions: the next step has no dV/dt term. For when the boundary
  // is redefined (a moved fictitious wall is not a change of pore volume).
  void reset_history() { has_prev_ = false; }
  void request_bc_update() { bc_dirty_ = true; }
  bool remesh_due() const;
  bool has_mesh() const { return !cells_.volume.empty(); }

  // Results of the last step.
  const std::vector<Vec3>& forces() const { return force_; }  // spheres, then six walls
  const std::vector<double>& pressure() const { return pressure_; }
  const Mesh& mesh() const { return tri_.mesh(); }
  const CellGeometry& cells() const { return cells_; }
  const FacetGeometry& facets() const { return facets_; }
  const std::vector<double>& conductances() const { return k_; }
  const PressureSystem& system() const { return system_; }
  const BoxWalls& walls() const { return walls_prev_; }
  double boundary_flux(int wall) const;
  double imposed_flux_total() const;
  double volume_rate_total() const;  // sum of dV/dt over the unknown cells
  double average_pressure() const;
  double average_slice_pressure(int axis, double position) const;
  int locate(const Vec3& x) const { return tri_.locate(x); }
  bool metis_used() const { return cholmod_->metis_used(); }
  const CholmodSolver& cholmod() const { return *cholmod_; }
  int remesh_count() const { return remesh_count_; }
  double accumulated_strain() const { return strain_; }
  int gs_iterations() const { return gs_iterations_; }
  const StageTimes& remesh_times() const { return remesh_times_; }
  const StageTimes& step_times() const { return step_times_; }

 private:
  void remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
              const BoxWalls& walls);
  void rebuild_system();

  RegularTriangulation tri_;
  CellGeometry cells_;
  FacetGeometry facets_;
  std::vector<double> k_;
  PressureSystem system_;
  std::vector<std::array<double, 2>> dirichlet_coupling_;  // (unknown, k) per Dirichlet link
  std::vector<int> dirichlet_coupling_cell_;
  std::unique_ptr<CholmodSolver> cholmod_ = std::make_unique<CholmodSolver>();
  ForceCache cache_;
  std::vector<int> imposed_pressure_cells_, imposed_flux_cells_;

  std::vector<double> pressure_, volume_, volume_rate_, rhs_, solution_;
  std::vector<Vec3> force_;
  std::vector<double> next_volume_, next_pressure_;  // scratch of the step being computed
  std::vector<Vec3> next_force_;
  std::vector<Vec3> centres_prev_;
  BoxWalls walls_prev_;
  bool has_prev_ = false;
  double strain_ = 0;
  double mean_cell_volume_ = 0;
  int steps_since_remesh_ = 0;
  int remesh_count_ = 0;
  int gs_iterations_ = 0;
  bool remesh_requested_ = true;
  bool bc_dirty_ = false;
  StageTimes remesh_times_, step_times_;
};

// Checks a scene snapshot; throws std::invalid_argument naming the first problem.
void validate_snapshot(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                       const BoxWalls& walls);

}  // namespace pfv
