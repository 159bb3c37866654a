// The products of a remesh, built from one snapshot and independent of the engine's state:
// the pore mesh (triangulation, geometry, conductances, force cache, viscous shear pairs) and the linear system
// over it (assembly and factorisation for given boundary conditions). Building them touches
// nothing shared, so a remesh can run on another thread.
#pragma once
#include <memory>
#include <optional>
#include <vector>

#include "boundary_conditions.hpp"
#include "engine_settings.hpp"
#include "force_cache.hpp"
#include "ordering_reuse.hpp"
#include "pcg_solver.hpp"
#include "refinement.hpp"
#include "pore_geometry.hpp"
#include "pressure_system.hpp"
#include "regular_triangulation.hpp"
#include "viscous_shear.hpp"

namespace pfv {

struct PoreMesh {
  RegularTriangulation tri;
  CellGeometry cells;
  FacetGeometry facets;
  std::vector<double> k;
  ForceCache cache;
  std::optional<ViscousShear> shear;  // only with settings.viscous_shear
  double mean_cell_volume = 0;
  StageTimes times;  // triangulation, geometry, conductance, force_cache, shear_geometry

  const Mesh& mesh() const { return tri.mesh(); }
};

struct LinearSystem {
  PressureSystem system;
  std::vector<int> coupling_unknown, coupling_cell;  // Dirichlet neighbours of unknowns
  std::vector<double> coupling_k;
  std::unique_ptr<CholmodSolver> cholmod = std::make_unique<CholmodSolver>();  // useSolver 3
  Refinement refinement;         // with a 32-bit factor
  bool mixed_precision = false;  // the settings the factor was built for
  double mixed_precision_min_entries = 0;
  std::shared_ptr<const CellOrdering> ordering;  // of the factor, for the next remesh
  PcgSolver pcg;                                                               // useSolver 1
  std::vector<int> imposed_pressure_cells, imposed_flux_cells;
  std::vector<double> storage;  // V_f / (K dt) per cell; empty for an incompressible fluid
  double dt = 0;                // the time step 'storage' was built for
  StageTimes times;  // assembly, analysis, factorization
};

// Throws std::invalid_argument for coincident centres or a centre inside another sphere.
PoreMesh build_pore_mesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                         const BoxWalls& walls, const EngineSettings& settings);

// Throws std::domain_error if the system is singular. previous: the ordering of the last
// factorisation, tried first when settings.reuse_ordering (null: compute one). solver: a
// released CholmodSolver to factorise with, whose storage is then reused (null: a new one).
LinearSystem build_linear_system(const PoreMesh& mesh, const BoundaryConditions& bc,
                                 const EngineSettings& settings, double dt,
                                 const CellOrdering* previous = nullptr,
                                 std::unique_ptr<CholmodSolver> solver = nullptr);

}  // namespace pfv
