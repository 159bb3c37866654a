// The flow through a periodic packing, one DEM step at a time (the engine of
// pfv.PeriodicFlowEngine): the periodic regular triangulation (periodic_triangulation.hpp), its
// pores and throats, the system G p~ = -dV/dt + s of periodic_pressure_system.hpp under the
// imposed macroscopic gradient, and the forces of periodic_forces.hpp.
//
// As the walled engine: the mesh, conductances, G and its factor are made at a remesh and kept;
// each step measures the cells' volumes at the spheres' positions and the cell's current
// vectors (the images follow both, so a homogeneous deformation of the cell, shear included,
// enters dV/dt), solves and applies the force cache. With a compressible fluid (bulk modulus K >
// 0) each pore stores V_f / (K dt) per unit pressure, G + that storage is positive definite, and
// p~ is absolute; incompressible, p~ = 0 in one reference pore (and a net change of the pores'
// volume has nowhere to go: the reference pore absorbs it).
#pragma once
#include <memory>
#include <vector>

#include "pfv/engine/stage_times.hpp"
#include "pfv/linalg/pressure_solver.hpp"
#include "pfv/model/boundary_conditions.hpp"
#include "pfv/model/force_cache.hpp"
#include "pfv/model/periodic_forces.hpp"
#include "pfv/model/periodic_pressure_system.hpp"
#include "triangulation/periodic_triangulation.hpp"
#include "triangulation/pore_geometry.hpp"

namespace pfv {

struct PeriodicFlowSettings {
  double viscosity = 1.0;
  double permeability_factor = 1.0;
  Vec3 gradient = Vec3::Zero();  // gradP, the imposed macroscopic pressure gradient
  double bulk_modulus = 0.0;     // of the fluid; 0: incompressible
  // The linear solver (pressure_solver.hpp; kAuto is not a choice here): the Cholesky factor
  // (METIS ordering), Gauss-Seidel or incomplete-Cholesky CG to `tolerance` (with `relax` for
  // Gauss-Seidel), or multigrid CG (built with hypre) to the refinement's bound.
  SolverKind solver = SolverKind::kCholesky;
  double tolerance = 1e-6;
  double relax = 1.9;
  // YADE's defTolerance: a remesh once the pores' strain summed over the steps since the last
  // (each step's largest |dV| / V of a cell, thesis 5.13) exceeds it; 0: off.
  double def_tolerance = 0.0;

  // Throws std::invalid_argument naming the setting that is not finite or out of range, or a
  // solver this build does not have.
  void validate() const;
};

class PeriodicFlow {
 public:
  // A cell thinner than this many of the largest sphere diameters along a period is refused:
  // a sphere would reach across half of it, and the pores would be those of a few spheres and
  // their own images rather than of a packing (YADE's collider refuses such cells too unless
  // allowBiggerThanPeriod).
  static constexpr double kMinWidthInDiameters = 2.0;

  PeriodicFlow();
  ~PeriodicFlow();

  // The settings take effect at the next step (a change of viscosity, permeability factor or
  // bulk modulus rebuilds G there, without a remesh). Throws std::invalid_argument as validate().
  void set_settings(const PeriodicFlowSettings& settings);
  const PeriodicFlowSettings& settings() const { return settings_; }

  // Point conditions (YADE's imposePressure, imposeFlux), kept through remeshes: each acts on
  // the pore holding its point, located at the remesh (any point, in any period). An imposed
  // pressure p sets the pore's p~ so that pressure_at(pos) is p; it fixes
  // the constant of p~ in place of the reference pore. Of two in one pore the later one holds.
  // A flux adds an inflow (volume per time) to its pore; incompressible and with no imposed
  // pressure, the reference pore takes the net inflow. Adding or clearing takes effect at the
  // next step (a new factor); set_imposed_pressure changes a value only. Throws
  // std::invalid_argument for a point or value that is not finite, std::out_of_range for an
  // index that is not a condition.
  int impose_pressure(const Vec3& pos, double p);
  void set_imposed_pressure(int index, double p);
  void clear_imposed_pressure();
  void impose_flux(const Vec3& pos, double inflow);
  void clear_imposed_flux();
  const std::vector<PointCondition>& imposed_pressures() const { return imposed_pressure_; }
  const std::vector<PointCondition>& imposed_fluxes() const { return imposed_flux_; }
  // Per cell of the mesh, 1 where an imposed pressure holds its pore (after a step), else 0.
  std::vector<int> imposed_cells() const;

  // Asks for a new mesh at the next step.
  void request_remesh() { remesh_due_ = true; }
  // The next step has no dV/dt term: the positions of the last step are not where this one's
  // motion started (a gap in the iterations, a scene loaded or replaced).
  void forget_motion() { has_previous_ = false; }
  bool has_mesh() const { return mesh_ != nullptr; }

  // One step of length dt with the spheres at centres (anywhere, unwrapped) and the cell's
  // vectors h: remesh if due (radii are read then), dV/dt from the last step's positions, solve,
  // forces. Throws std::invalid_argument on bad input before anything changes.
  void step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const Eigen::Matrix3d& h, double dt);

  const PeriodicMesh& mesh() const;
  // Per stored cell: p~, the full pressure p~ + gradP . P, dV/dt.
  const std::vector<double>& periodic_pressure() const { return periodic_pressure_; }
  std::vector<double> pressure() const;
  const std::vector<double>& volume_rates() const { return volume_rate_; }
  const std::vector<Vec3>& forces() const { return force_; }  // per sphere
  // The last step's positions of the mesh's images (PeriodicMesh::image_sphere), and the stored
  // cells' volumes at them.
  const std::vector<Vec3>& image_positions() const { return images_; }
  const Eigen::Matrix3d& step_cell() const { return h_; }  // the cell's vectors of the last step
  const std::vector<double>& current_volumes() const { return volume_; }
  // The superficial velocity (1/V) sum_f q_f d_f.
  Vec3 mean_velocity() const;
  // The throats of the current mesh (needs a mesh): their geometry at the remesh, conductances,
  // and the flux of the last step's pressure from cell[f][0] to cell[f][1] (NaN before a solve).
  const FacetGeometry& facets() const;
  const std::vector<double>& conductances() const;
  std::vector<double> throat_fluxes() const;
  // Per facet, the radius of its constriction (triangulation/constriction.hpp) at the remesh.
  std::vector<double> throat_constrictions() const;
  // The pressure of the pore holding x (anywhere, in any period): p~ + gradP . P, P the power
  // centre of that pore's translate (a cell's pressure, as YADE's getPorePressure); NaN before
  // the first step.
  double pressure_at(const Vec3& x) const;
  int remesh_count() const { return remeshes_; }
  // The pores' strain summed since the last remesh (def_tolerance).
  double strain() const { return strain_; }
  // Seconds per stage of the last remesh (triangulation, geometry, force_cache, conductance,
  // assembly, factorization: ordering included) and of the last step (volumes, solve, forces,
  // total: the remesh included if the step made one).
  const StageTimes& remesh_times() const { return remesh_times_; }
  const StageTimes& step_times() const { return step_times_; }

  // What a run needs to go on exactly where it stopped (a saved and reloaded scene): the input
  // of the current mesh, the last step's positions and cell, and p~. resume() rebuilds the same
  // mesh (the triangulation is a function of its input) and restores the rest, so that the next
  // step equals the uninterrupted run's, cells numbered as before.
  struct RunState {
    std::vector<Vec3> mesh_centres;
    std::vector<double> mesh_radii;
    Eigen::Matrix3d mesh_h = Eigen::Matrix3d::Identity();
    std::vector<Vec3> previous_centres;  // empty: no dV/dt history
    Eigen::Matrix3d previous_h = Eigen::Matrix3d::Identity();
    std::vector<double> periodic_pressure;  // per cell of the mesh
    double strain = 0;                      // the pores' strain since the mesh was made
  };
  RunState run_state() const;  // needs a mesh
  // Throws std::invalid_argument for a state whose input a step would refuse, or whose pressures
  // do not match the rebuilt mesh; the engine is then left as it was.
  void resume(const RunState& state);
  // Per stored cell, its fluid volume at the remesh (what the storage of a compressible fluid uses).
  const std::vector<double>& fluid_volumes() const;
  // The stored cells' geometry at the remesh (volumes, power centres); needs a mesh.
  const CellGeometry& cells() const;

 private:
  struct Meshed;  // what a remesh makes: triangulation, geometry, system, factor, force cache
  void check_mesh_input(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                        const Eigen::Matrix3d& h) const;
  std::unique_ptr<Meshed> build_mesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                     const Eigen::Matrix3d& h);
  void remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const Eigen::Matrix3d& h);
  void build_system(double dt);
  // volume_ of the current mesh's cells at the last step's positions (centres_, h_).
  void measure_previous_volumes();
  // Per cell, the known p~ of the reference pore (0) and of the imposed pores; the rest 0. Made
  // with the gradient's source: per system, gradient and imposed value, not per step.
  std::vector<double> known_pressures() const;
  // The power centre of the located cell's translate that holds the point.
  Vec3 located_centre(const PeriodicTriangulation::Location& where) const;
  void image_positions(const std::vector<Vec3>& centres, const Eigen::Matrix3d& h, std::vector<Vec3>& out) const;

  PeriodicFlowSettings settings_;
  std::unique_ptr<Meshed> mesh_;
  bool remesh_due_ = true, system_due_ = true, source_due_ = true, has_previous_ = false;
  double system_dt_ = 0, strain_ = 0, mean_cell_volume_ = 0;
  int remeshes_ = 0;
  Eigen::Matrix3d h_ = Eigen::Matrix3d::Identity();
  std::vector<Vec3> centres_, images_;  // the last step's
  std::vector<double> volume_, volume_rate_, periodic_pressure_, storage_;
  std::vector<Vec3> force_;
  std::vector<PointCondition> imposed_pressure_, imposed_flux_;
  StageTimes remesh_times_, step_times_;
};

}  // namespace pfv
