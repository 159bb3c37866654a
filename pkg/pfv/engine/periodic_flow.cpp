#include "pfv/engine/periodic_flow.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/model/conductance.hpp"

namespace pfv {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// One period's cells at the given image positions, each oriented as when it was meshed.
double tetrahedron_volume(const std::array<int, 4>& v, const std::vector<Vec3>& x) {
  return (x[v[1]] - x[v[0]]).dot((x[v[2]] - x[v[0]]).cross(x[v[3]] - x[v[0]])) / 6.0;
}

}  // namespace

void PeriodicFlowSettings::validate() const {
  require(std::isfinite(viscosity) && viscosity > 0, "viscosity must be positive and finite");
  require(std::isfinite(permeability_factor) && permeability_factor > 0,
          "permeabilityFactor must be positive and finite");
  require(gradient.allFinite(), "gradP must be finite");
  require(std::isfinite(bulk_modulus) && bulk_modulus >= 0, "fluidBulkModulus must be finite and not negative");
}

struct PeriodicFlow::Meshed {
  PeriodicTriangulation triangulation;
  CellGeometry cells;
  FacetGeometry facets;
  std::vector<double> conductance;
  std::vector<double> gradient_source;  // s of the imposed gradient: per system and gradient, not per step
  std::vector<double> orientation;      // per cell, the sign of its volume when meshed
  PeriodicPressureSystem system;
  ForceCache cache;
  PeriodicForces forces;
  std::unique_ptr<PressureSolver> solver;

  const PeriodicMesh& periodic() const { return triangulation.mesh(); }
};

PeriodicFlow::PeriodicFlow() = default;
PeriodicFlow::~PeriodicFlow() = default;

void PeriodicFlow::set_settings(const PeriodicFlowSettings& s) {
  s.validate();
  if (s.viscosity != settings_.viscosity || s.permeability_factor != settings_.permeability_factor ||
      s.bulk_modulus != settings_.bulk_modulus)
    system_due_ = true;
  if (s.gradient != settings_.gradient) source_due_ = true;
  settings_ = s;
}

const PeriodicMesh& PeriodicFlow::mesh() const {
  if (!mesh_) throw std::logic_error("PeriodicFlow: no mesh before the first step");
  return mesh_->periodic();
}

void PeriodicFlow::image_positions(const std::vector<Vec3>& centres, const Eigen::Matrix3d& h,
                                   std::vector<Vec3>& out) const {
  const PeriodicMesh& m = mesh_->periodic();
  out.resize(m.n_images());
  for (int v = 0; v < m.n_images(); ++v) {
    const int s = m.image_sphere[v];
    const Offset& w = m.wrap[s];
    const Offset& o = m.image_offset[v];
    out[v] = centres[s] + h * Vec3(w[0] + o[0], w[1] + o[1], w[2] + o[2]);
  }
}

void PeriodicFlow::step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const Eigen::Matrix3d& h,
                        double dt) {
  // Everything checked before anything changes.
  require(std::isfinite(dt) && dt > 0, "the time step must be positive and finite");
  require(h.allFinite() && h.determinant() > 0, "the cell's vectors (hSize) must be finite and right-handed");
  require(!centres.empty(), "no spheres");
  for (std::size_t s = 0; s < centres.size(); ++s)
    require(centres[s].allFinite(), "sphere " + std::to_string(s) + " has a non-finite position");
  const bool remeshing = remesh_due_ || !mesh_ || mesh_->periodic().n_spheres != static_cast<int>(centres.size());
  if (remeshing) {
    require(radii.size() == centres.size(),
            std::to_string(radii.size()) + " radii for " + std::to_string(centres.size()) + " spheres");
    double largest = 0;
    for (std::size_t s = 0; s < radii.size(); ++s) {
      require(std::isfinite(radii[s]) && radii[s] > 0, "sphere " + std::to_string(s) +
                                                           " has a radius that is not "
                                                           "positive and finite");
      largest = std::max(largest, radii[s]);
    }
    const PeriodicCell cell{h};
    for (int a = 0; a < 3; ++a)
      require(cell.width(a) >= kMinWidthInDiameters * 2 * largest,
              "the periodic cell is " + std::to_string(cell.width(a)) + " thick across its vector " +
                  std::to_string(a) + ", less than " + std::to_string(kMinWidthInDiameters) +
                  " diameters of its largest sphere (" + std::to_string(2 * largest) + ")");
    remesh(centres, radii, h);
  }
  if (system_due_ || (settings_.bulk_modulus > 0 && dt != system_dt_)) build_system(dt);
  if (source_due_) {
    mesh_->gradient_source = gradient_source(mesh_->cells, mesh_->facets, mesh_->conductance, settings_.gradient);
    source_due_ = false;
  }

  const PeriodicMesh& m = mesh_->periodic();
  const int nc = m.n_cells();
  image_positions(centres, h, images_);
  volume_rate_.assign(nc, 0.0);
  std::vector<double> volume(nc);
  for (int c = 0; c < nc; ++c) {
    volume[c] = mesh_->orientation[c] * tetrahedron_volume(m.mesh.cell_vertices[c], images_);
    if (has_previous_) volume_rate_[c] = (volume[c] - volume_[c]) / dt;
  }
  std::vector<double> per_cell = mesh_->gradient_source;
  for (int c = 0; c < nc; ++c) {
    per_cell[c] -= volume_rate_[c];
    if (!storage_.empty()) per_cell[c] += storage_[c] * periodic_pressure_[c];
  }
  const PeriodicPressureSystem& system = mesh_->system;
  std::vector<double> x = system.gather(periodic_pressure_);
  if (system.n_unknowns() > 0) {  // else the cell is one pore, at its reference pressure
    std::vector<double> b = system.gather(per_cell);
    mesh_->solver->solve(b, x, SolveControl{});
  }
  periodic_pressure_ = system.scatter(x);
  force_ = mesh_->forces.apply(mesh_->cache, m, pressure(), settings_.gradient, m.cell.h);
  volume_ = std::move(volume);
  centres_ = centres;
  h_ = h;
  has_previous_ = true;
}

void PeriodicFlow::remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                          const Eigen::Matrix3d& h) {
  auto next = std::make_unique<Meshed>();
  const PeriodicMesh& m = next->triangulation.build(centres, radii, PeriodicCell{h});
  static const BoxWalls no_walls{};
  const Packing packing{m.image_centre, m.image_radius, no_walls, &m.cell.h};
  next->cells = compute_cell_geometry(m.mesh, packing);
  next->facets = compute_facet_geometry(m.mesh, next->cells, packing, false);
  next->orientation.resize(m.n_cells());
  for (int c = 0; c < m.n_cells(); ++c)
    next->orientation[c] = tetrahedron_volume(m.mesh.cell_vertices[c], m.image_centre) < 0 ? -1.0 : 1.0;
  next->cache.build(m.mesh, next->facets, packing);
  next->forces.build(next->cache, m);
  // The pressures carried over by position: each new cell takes the pressure p~ + gradP . x of
  // the old mesh at its power centre, less the gradient's part at the new centre.
  std::vector<double> carried(m.n_cells(), 0.0);
  if (mesh_)
    for (int c = 0; c < m.n_cells(); ++c) {
      const Vec3& x = next->cells.power_centre[c];
      carried[c] = pressure_at(x) - settings_.gradient.dot(x);
      if (!std::isfinite(carried[c])) carried[c] = 0.0;
    }
  const bool previous = has_previous_ && mesh_ && centres_.size() == centres.size();
  mesh_ = std::move(next);
  periodic_pressure_ = std::move(carried);
  // The reference of the next step's dV/dt: the new cells at the last step's positions.
  has_previous_ = previous;
  if (previous) {
    std::vector<Vec3> before;
    image_positions(centres_, h_, before);
    volume_.resize(m.n_cells());
    for (int c = 0; c < m.n_cells(); ++c)
      volume_[c] = mesh_->orientation[c] * tetrahedron_volume(m.mesh.cell_vertices[c], before);
  }
  remesh_due_ = false;
  system_due_ = true;
  ++remeshes_;
}

void PeriodicFlow::build_system(double dt) {
  Meshed& mesh = *mesh_;
  ConductanceModel model;
  model.viscosity = settings_.viscosity;
  model.permeability_factor = settings_.permeability_factor;
  mesh.conductance = throat_conductances(mesh.facets, model);
  storage_.clear();
  if (settings_.bulk_modulus > 0) {
    storage_.resize(mesh.cells.fluid_volume.size());
    for (std::size_t c = 0; c < storage_.size(); ++c)
      storage_[c] = mesh.cells.fluid_volume[c] / (settings_.bulk_modulus * dt);
  }
  mesh.system = assemble_periodic_system(mesh.periodic().mesh, mesh.facets, mesh.conductance, storage_);
  mesh.solver.reset();
  if (mesh.system.n_unknowns() > 0) {
    // METIS orders the periodic graph as it is; the geometric dissection cuts by planes, which
    // the pores' graph crosses through every period.
    SolverOptions options;
    options.factor.ordering = Ordering::kMetis;
    mesh.solver = std::make_unique<CholeskySolver>();
    mesh.solver->setup(mesh.system.matrix, options);
  }
  system_dt_ = dt;
  system_due_ = false;
  source_due_ = true;  // new conductances
}

std::vector<double> PeriodicFlow::pressure() const {
  if (!mesh_) return {};
  return full_pressure(mesh_->cells, periodic_pressure_, settings_.gradient);
}

Vec3 PeriodicFlow::mean_velocity() const {
  if (!mesh_ || periodic_pressure_.empty()) return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  const auto q =
      periodic_fluxes(mesh_->cells, mesh_->facets, mesh_->conductance, periodic_pressure_, settings_.gradient);
  return pfv::mean_velocity(mesh_->cells, mesh_->facets, q, mesh_->periodic().cell.volume());
}

double PeriodicFlow::pressure_at(const Vec3& x) const {
  if (!mesh_ || periodic_pressure_.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto where = mesh_->triangulation.locate(x);
  if (where.cell < 0) return std::numeric_limits<double>::quiet_NaN();
  return periodic_pressure_[where.cell] + settings_.gradient.dot(x);
}

const std::vector<double>& PeriodicFlow::fluid_volumes() const {
  static const std::vector<double> none;
  return mesh_ ? mesh_->cells.fluid_volume : none;
}

}  // namespace pfv
