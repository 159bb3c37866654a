// The geometric products of a remesh, built from one snapshot and independent of the engine's
// state: triangulation, cell and throat geometry, conductances, the force cache and the
// viscous shear pairs. Building them touches nothing shared, so a remesh can run on another
// thread. The linear system over them is linear_system.hpp.
#pragma once
#include <optional>
#include <vector>

#include "pfv/engine/engine_settings.hpp"
#include "pfv/engine/stage_times.hpp"
#include "pfv/model/force_cache.hpp"
#include "pfv/model/viscous_shear.hpp"
#include "triangulation/pore_geometry.hpp"
#include "triangulation/regular_triangulation.hpp"

namespace pfv {

// The settings a pore mesh depends on.
struct MeshRecipe {
  ConductanceModel conductance;
  bool slip_boundary = true;
  bool viscous_shear = false;
  bool yade_wall_throat_factor = true;

  explicit MeshRecipe(const EngineSettings& s)
      : conductance(s.conductance),
        slip_boundary(s.slip_boundary),
        viscous_shear(s.viscous_shear),
        yade_wall_throat_factor(s.yade_wall_throat_factor) {}
  // Whether a mesh built from this recipe must be rebuilt for 's'. The viscosity is not
  // compared: every conductance is inversely proportional to it (the clamp is relative to the
  // median), so a change rescales them (PoreMesh::set_viscosity) without a new triangulation.
  // Switching viscous_shear off needs no remesh: the engine drops the pairs and clears
  // viscous_shear here.
  bool stale_for(const EngineSettings& s) const;
};

// The positions a mesh was built from: enough to build the same mesh again (a resumed run).
struct MeshSource {
  std::vector<Vec3> centres;
  std::vector<double> radii;
  BoxWalls walls;
};

struct PoreMesh {
  MeshSource source;
  RegularTriangulation tri;
  CellGeometry cells;
  FacetGeometry facets;
  std::vector<double> k;
  ForceCache cache;
  std::optional<ViscousShear> shear;  // only with settings.viscous_shear
  double mean_cell_volume = 0;
  StageTimes times;  // triangulation, geometry, conductance, force_cache, shear_geometry
  MeshRecipe recipe;

  explicit PoreMesh(const EngineSettings& s) : recipe(s) {}
  const Mesh& mesh() const { return tri.mesh(); }
  double viscosity() const { return recipe.conductance.viscosity; }
  // The conductances for another viscosity: k scales as 1 / mu.
  void set_viscosity(double mu);
};

// Throws std::invalid_argument for coincident centres or a centre inside another sphere.
PoreMesh build_pore_mesh(const std::vector<Vec3>& centres, const std::vector<double>& radii, const BoxWalls& walls,
                         const EngineSettings& settings);

}  // namespace pfv
