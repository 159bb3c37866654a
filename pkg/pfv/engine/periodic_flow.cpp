#include "pfv/engine/periodic_flow.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "pfv/common/stage_timer.hpp"
#include "pfv/engine/solver_policy.hpp"
#include "pfv/model/conductance.hpp"
#include "triangulation/constriction.hpp"

namespace pfv {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

// One period's cells at the given image positions, each oriented as when it was meshed.
double tetrahedron_volume(const std::array<int, 4>& v, const std::vector<Vec3>& x) {
  return (x[v[1]] - x[v[0]]).dot((x[v[2]] - x[v[0]]).cross(x[v[3]] - x[v[0]])) / 6.0;
}

void check_positions(const std::vector<Vec3>& centres, const Eigen::Matrix3d& h) {
  require(h.allFinite() && h.determinant() > 0, "the cell's vectors (hSize) must be finite and right-handed");
  require(!centres.empty(), "no spheres");
  for (std::size_t s = 0; s < centres.size(); ++s)
    require(centres[s].allFinite(), "sphere " + std::to_string(s) + " has a non-finite position");
}

}  // namespace

void PeriodicFlowSettings::validate() const {
  require(std::isfinite(viscosity) && viscosity > 0, "viscosity must be positive and finite");
  require(std::isfinite(permeability_factor) && permeability_factor > 0,
          "permeabilityFactor must be positive and finite");
  require(gradient.allFinite(), "gradP must be finite");
  require(std::isfinite(bulk_modulus) && bulk_modulus >= 0, "fluidBulkModulus must be finite and not negative");
  require(solver != SolverKind::kAuto, "the periodic engine's solver must be named (no automatic choice)");
  const std::string unavailable = solver_unavailable(solver);
  require(unavailable.empty(), unavailable);
  require(std::isfinite(tolerance) && tolerance > 0, "tolerance must be positive and finite");
  require(std::isfinite(relax) && relax > 0 && relax < 2, "relax must be in (0, 2)");
  require(std::isfinite(def_tolerance) && def_tolerance >= 0, "defTolerance must be finite and not negative");
}

struct PeriodicFlow::Meshed {
  // The input, for run_state().
  std::vector<Vec3> centres;
  std::vector<double> radii;
  Eigen::Matrix3d h;
  PeriodicTriangulation triangulation;
  CellGeometry cells;
  FacetGeometry facets;
  std::vector<double> conductance;
  std::vector<double> gradient_source;  // s of the imposed gradient: per system and gradient, not per step
  std::vector<double> known;            // p~ of the known pores per cell (known_pressures): likewise
  std::vector<double> orientation;      // per cell, the sign of its volume when meshed
  // Per image, its sphere's wrap plus its own offset in periods (wrap + o_v): each step's image
  // is the sphere's centre plus h times this.
  std::vector<Vec3> image_translation;
  double mean_cell_volume = 0;
  PeriodicPressureSystem system;
  ForceCache cache;
  PeriodicForces forces;
  std::unique_ptr<PressureSolver> solver;
  // Per point condition, the cell holding its point (located when the system is built).
  std::vector<int> pressure_cell, flux_cell;
  std::vector<Vec3> pressure_centre;  // the power centre of the imposed pore's translate holding the point

  const PeriodicMesh& periodic() const { return triangulation.mesh(); }
};

PeriodicFlow::PeriodicFlow() = default;
PeriodicFlow::~PeriodicFlow() = default;

void PeriodicFlow::set_settings(const PeriodicFlowSettings& s) {
  s.validate();
  if (s.viscosity != settings_.viscosity || s.permeability_factor != settings_.permeability_factor ||
      s.bulk_modulus != settings_.bulk_modulus || s.solver != settings_.solver)
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
  const std::vector<Vec3>& translation = mesh_->image_translation;
  out.resize(m.n_images());
  for (int v = 0; v < m.n_images(); ++v) out[v] = centres[m.image_sphere[v]] + h * translation[v];
}

void PeriodicFlow::check_mesh_input(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                    const Eigen::Matrix3d& h) const {
  check_positions(centres, h);
  require(radii.size() == centres.size(),
          std::to_string(radii.size()) + " radii for " + std::to_string(centres.size()) + " spheres");
  double largest = 0;
  for (std::size_t s = 0; s < radii.size(); ++s) {
    require(std::isfinite(radii[s]) && radii[s] > 0,
            "sphere " + std::to_string(s) + " has a radius that is not positive and finite");
    largest = std::max(largest, radii[s]);
  }
  const PeriodicCell cell{h};
  for (int a = 0; a < 3; ++a)
    require(cell.width(a) >= kMinWidthInDiameters * 2 * largest,
            "the periodic cell is " + std::to_string(cell.width(a)) + " thick across its vector " + std::to_string(a) +
                ", less than " + std::to_string(kMinWidthInDiameters) + " diameters of its largest sphere (" +
                std::to_string(2 * largest) + ")");
}

void PeriodicFlow::step(const std::vector<Vec3>& centres, const std::vector<double>& radii, const Eigen::Matrix3d& h,
                        double dt) {
  const auto start = StageClock::now();
  // Everything checked before anything changes.
  require(std::isfinite(dt) && dt > 0, "the time step must be positive and finite");
  check_positions(centres, h);
  const bool remeshing = remesh_due_ || !mesh_ || mesh_->periodic().n_spheres != static_cast<int>(centres.size());
  if (remeshing) {
    check_mesh_input(centres, radii, h);
    remesh(centres, radii, h);
  }
  step_times_ = StageTimes{};
  if (system_due_ || (settings_.bulk_modulus > 0 && dt != system_dt_)) build_system(dt);
  if (source_due_) {
    mesh_->gradient_source = gradient_source(mesh_->cells, mesh_->facets, mesh_->conductance, settings_.gradient);
    mesh_->known = known_pressures();
    source_due_ = false;
  }

  auto t0 = StageClock::now();
  const PeriodicMesh& m = mesh_->periodic();
  const int nc = m.n_cells();
  image_positions(centres, h, images_);
  volume_rate_.assign(nc, 0.0);
  std::vector<double> volume(nc);
  // The pores' strain of the step as the walled engine measures it: a sliver's volume counts as the
  // mean, so that its small motions are not large strains.
  double max_change = 0;
  for (int c = 0; c < nc; ++c) {
    volume[c] = mesh_->orientation[c] * tetrahedron_volume(m.mesh.cell_vertices[c], images_);
    if (!has_previous_) continue;
    const double dv = volume[c] - volume_[c];
    volume_rate_[c] = dv / dt;
    max_change = std::max(max_change, std::abs(dv) / std::max(volume[c], mesh_->mean_cell_volume));
  }
  step_times_.volumes = seconds_since(t0);
  t0 = StageClock::now();
  std::vector<double> per_cell = mesh_->gradient_source;
  for (int c = 0; c < nc; ++c) {
    per_cell[c] -= volume_rate_[c];
    if (!storage_.empty()) per_cell[c] += storage_[c] * periodic_pressure_[c];
  }
  for (std::size_t i = 0; i < imposed_flux_.size(); ++i) per_cell[mesh_->flux_cell[i]] += imposed_flux_[i].value;
  const PeriodicPressureSystem& system = mesh_->system;
  const std::vector<double>& known = mesh_->known;
  std::vector<double> x = system.gather(periodic_pressure_);
  if (system.n_unknowns() > 0) {  // else every pore is known (the cell is one pore, or all imposed)
    std::vector<double> b = system.gather(per_cell);
    system.add_known(known, b);
    SolveControl control;
    control.tolerance = settings_.tolerance;
    control.relax = settings_.relax;
    control.time_step = dt;
    mesh_->solver->solve(b, x, control);
  }
  periodic_pressure_ = system.scatter(x, known);
  step_times_.solve = seconds_since(t0);
  t0 = StageClock::now();
  force_ = mesh_->forces.apply(mesh_->cache, m, pressure(), settings_.gradient, m.cell.h);
  step_times_.forces = seconds_since(t0);
  volume_ = std::move(volume);
  centres_ = centres;
  h_ = h;
  has_previous_ = true;
  strain_ += max_change;
  if (settings_.def_tolerance > 0 && strain_ > settings_.def_tolerance) remesh_due_ = true;
  step_times_.total = seconds_since(start);
}

std::vector<double> PeriodicFlow::known_pressures() const {
  const PeriodicPressureSystem& system = mesh_->system;
  std::vector<double> pore_value(mesh_->periodic().n_cells(), 0.0);
  for (std::size_t i = 0; i < imposed_pressure_.size(); ++i)
    pore_value[system.pore[mesh_->pressure_cell[i]]] =
        imposed_pressure_[i].value - settings_.gradient.dot(mesh_->pressure_centre[i]);
  std::vector<double> known(system.pore.size());
  for (std::size_t c = 0; c < known.size(); ++c) known[c] = pore_value[system.pore[c]];
  return known;
}

std::unique_ptr<PeriodicFlow::Meshed> PeriodicFlow::build_mesh(const std::vector<Vec3>& centres,
                                                               const std::vector<double>& radii,
                                                               const Eigen::Matrix3d& h) {
  remesh_times_ = StageTimes{};
  auto t0 = StageClock::now();
  auto next = std::make_unique<Meshed>();
  next->centres = centres;
  next->radii = radii;
  next->h = h;
  const PeriodicMesh& m = next->triangulation.build(centres, radii, PeriodicCell{h});
  remesh_times_.triangulation = seconds_since(t0);
  t0 = StageClock::now();
  static const BoxWalls no_walls{};
  const Packing packing{m.image_centre, m.image_radius, no_walls, &m.cell.h};
  next->cells = compute_cell_geometry(m.mesh, packing);
  next->facets = compute_facet_geometry(m.mesh, next->cells, packing, false);
  next->orientation.resize(m.n_cells());
  for (int c = 0; c < m.n_cells(); ++c)
    next->orientation[c] = tetrahedron_volume(m.mesh.cell_vertices[c], m.image_centre) < 0 ? -1.0 : 1.0;
  next->mean_cell_volume = m.cell.volume() / m.n_cells();
  next->image_translation.resize(m.n_images());
  for (int v = 0; v < m.n_images(); ++v) {
    const Offset& w = m.wrap[m.image_sphere[v]];
    const Offset& o = m.image_offset[v];
    next->image_translation[v] = Vec3(w[0] + o[0], w[1] + o[1], w[2] + o[2]);
  }
  remesh_times_.geometry = seconds_since(t0);
  t0 = StageClock::now();
  next->cache.build(m.mesh, next->facets, packing);
  next->forces.build(next->cache, m);
  remesh_times_.force_cache = seconds_since(t0);
  return next;
}

void PeriodicFlow::remesh(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                          const Eigen::Matrix3d& h) {
  auto next = build_mesh(centres, radii, h);
  const PeriodicMesh& m = next->periodic();
  // The pressures carried over by position: each new cell takes the pressure p~ + gradP . x of
  // the old mesh at its power centre, less the gradient's part at the new centre.
  const auto t0 = StageClock::now();
  std::vector<double> carried(m.n_cells(), 0.0);
  if (mesh_)
    for (int c = 0; c < m.n_cells(); ++c) {
      const Vec3& x = next->cells.power_centre[c];
      carried[c] = pressure_at(x) - settings_.gradient.dot(x);
      if (!std::isfinite(carried[c])) carried[c] = 0.0;
    }
  // A compressible fluid stores V_f p~ / K in its pores (the storage acts on p~): the carried
  // field is shifted so that the fluid-volume-weighted mean of p~, the closed cell's K dV / V_f,
  // goes on unchanged (carried by position alone it drifts a little at every remesh).
  if (mesh_ && settings_.bulk_modulus > 0 && !periodic_pressure_.empty()) {
    const auto weighted_mean = [](const std::vector<double>& volume, const std::vector<double>& p) {
      double sum = 0, total = 0;
      for (std::size_t c = 0; c < p.size(); ++c) {
        sum += volume[c] * p[c];
        total += volume[c];
      }
      return total > 0 ? sum / total : 0.0;
    };
    const double shift =
        weighted_mean(mesh_->cells.fluid_volume, periodic_pressure_) - weighted_mean(next->cells.fluid_volume, carried);
    for (double& p : carried) p += shift;
  }
  remesh_times_.carry_over = seconds_since(t0);
  const bool previous = has_previous_ && mesh_ && centres_.size() == centres.size();
  mesh_ = std::move(next);
  periodic_pressure_ = std::move(carried);
  // The reference of the next step's dV/dt: the new cells at the last step's positions.
  has_previous_ = previous;
  if (previous) measure_previous_volumes();
  remesh_due_ = false;
  system_due_ = true;
  strain_ = 0;
  ++remeshes_;
}

void PeriodicFlow::measure_previous_volumes() {
  const PeriodicMesh& m = mesh_->periodic();
  std::vector<Vec3> before;
  image_positions(centres_, h_, before);
  volume_.resize(m.n_cells());
  for (int c = 0; c < m.n_cells(); ++c)
    volume_[c] = mesh_->orientation[c] * tetrahedron_volume(m.mesh.cell_vertices[c], before);
}

PeriodicFlow::RunState PeriodicFlow::run_state() const {
  if (!mesh_) throw std::logic_error("PeriodicFlow: no run state before the first step");
  RunState state;
  state.mesh_centres = mesh_->centres;
  state.mesh_radii = mesh_->radii;
  state.mesh_h = mesh_->h;
  if (has_previous_) {
    state.previous_centres = centres_;
    state.previous_h = h_;
  }
  state.periodic_pressure = periodic_pressure_;
  state.strain = strain_;
  return state;
}

void PeriodicFlow::resume(const RunState& state) {
  check_mesh_input(state.mesh_centres, state.mesh_radii, state.mesh_h);
  const bool previous = !state.previous_centres.empty();
  if (previous) {
    require(state.previous_centres.size() == state.mesh_centres.size(),
            "the run state's previous positions are not those of its mesh's spheres");
    require(state.previous_h.allFinite() && state.previous_h.determinant() > 0,
            "the run state's previous cell vectors must be finite and right-handed");
    for (const Vec3& c : state.previous_centres) require(c.allFinite(), "the run state has a non-finite position");
  }
  auto next = build_mesh(state.mesh_centres, state.mesh_radii, state.mesh_h);
  require(static_cast<int>(state.periodic_pressure.size()) == next->periodic().n_cells(),
          "the run state's " + std::to_string(state.periodic_pressure.size()) + " pressures do not match the " +
              std::to_string(next->periodic().n_cells()) + " cells of its rebuilt mesh");
  for (double p : state.periodic_pressure) require(std::isfinite(p), "the run state has a non-finite pressure");
  require(std::isfinite(state.strain) && state.strain >= 0, "the run state's strain must be finite and not negative");
  mesh_ = std::move(next);
  periodic_pressure_ = state.periodic_pressure;
  has_previous_ = previous;
  if (previous) {
    centres_ = state.previous_centres;
    h_ = state.previous_h;
    measure_previous_volumes();
  }
  remesh_due_ = false;
  system_due_ = true;
  strain_ = state.strain;
  ++remeshes_;
}

std::vector<int> PeriodicFlow::imposed_cells() const {
  if (!mesh_) return {};
  const std::vector<int>& pore = mesh_->system.pore;
  std::vector<int> imposed_pore(pore.size(), 0), out(pore.size(), 0);
  for (int c : mesh_->pressure_cell) imposed_pore[pore[c]] = 1;
  for (std::size_t c = 0; c < pore.size(); ++c) out[c] = imposed_pore[pore[c]];
  return out;
}

int PeriodicFlow::impose_pressure(const Vec3& pos, double p) {
  require(pos.allFinite(), "imposePressure: the point must be finite");
  require(std::isfinite(p), "imposePressure: the pressure must be finite");
  imposed_pressure_.push_back({pos, p});
  system_due_ = true;
  return static_cast<int>(imposed_pressure_.size()) - 1;
}

void PeriodicFlow::set_imposed_pressure(int index, double p) {
  if (index < 0 || index >= static_cast<int>(imposed_pressure_.size()))
    throw std::out_of_range("setImposedPressure: no imposed pressure " + std::to_string(index) + " (there are " +
                            std::to_string(imposed_pressure_.size()) + ")");
  require(std::isfinite(p), "setImposedPressure: the pressure must be finite");
  imposed_pressure_[index].value = p;
  source_due_ = true;  // the known pressures
}

void PeriodicFlow::clear_imposed_pressure() {
  if (!imposed_pressure_.empty()) system_due_ = true;
  imposed_pressure_.clear();
}

void PeriodicFlow::impose_flux(const Vec3& pos, double inflow) {
  require(pos.allFinite(), "imposeFlux: the point must be finite");
  require(std::isfinite(inflow), "imposeFlux: the flux must be finite");
  imposed_flux_.push_back({pos, inflow});
  system_due_ = true;
}

void PeriodicFlow::clear_imposed_flux() {
  imposed_flux_.clear();
  system_due_ = true;
}

void PeriodicFlow::build_system(double dt) {
  auto t0 = StageClock::now();
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
  const auto locate = [&](const std::vector<PointCondition>& points, std::vector<int>& cell,
                          std::vector<Vec3>* centre) {
    cell.resize(points.size());
    if (centre) centre->resize(points.size());
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto where = mesh.triangulation.locate(points[i].position);
      if (where.cell < 0) throw std::logic_error("PeriodicFlow: a condition's point is in no cell of the mesh");
      cell[i] = where.cell;
      if (centre) (*centre)[i] = located_centre(where);
    }
  };
  locate(imposed_pressure_, mesh.pressure_cell, &mesh.pressure_centre);
  locate(imposed_flux_, mesh.flux_cell, nullptr);
  step_times_.conductance = seconds_since(t0);
  t0 = StageClock::now();
  mesh.system =
      assemble_periodic_system(mesh.periodic().mesh, mesh.facets, mesh.conductance, storage_, mesh.pressure_cell);
  step_times_.assembly = seconds_since(t0);
  t0 = StageClock::now();
  mesh.solver.reset();
  if (mesh.system.n_unknowns() > 0) {
    // Small systems as CHOLMOD's rule orders them (AMD: an analysis several times cheaper than
    // METIS's, for a factor that solves about as fast; cholmod_solver.hpp), larger ones by METIS on
    // the periodic graph as it is (the geometric dissection cuts by planes, which the pores' graph
    // crosses through every period).
    SolverOptions options;
    options.factor.ordering = mesh.system.n_unknowns() < kGeometricFrom ? Ordering::kCholmod : Ordering::kMetis;
    mesh.solver = make_solver(settings_.solver);
    mesh.solver->setup(mesh.system.matrix, options);
  }
  step_times_.factorization = seconds_since(t0);
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
  return pfv::mean_velocity(mesh_->cells, mesh_->facets, throat_fluxes(), mesh_->periodic().cell.volume());
}

const FacetGeometry& PeriodicFlow::facets() const {
  if (!mesh_) throw std::logic_error("PeriodicFlow: no mesh before the first step");
  return mesh_->facets;
}

const std::vector<double>& PeriodicFlow::conductances() const {
  if (!mesh_) throw std::logic_error("PeriodicFlow: no mesh before the first step");
  return mesh_->conductance;
}

std::vector<double> PeriodicFlow::throat_fluxes() const {
  if (!mesh_) throw std::logic_error("PeriodicFlow: no mesh before the first step");
  if (periodic_pressure_.empty())
    return std::vector<double>(mesh_->facets.size(), std::numeric_limits<double>::quiet_NaN());
  return periodic_fluxes(mesh_->cells, mesh_->facets, mesh_->conductance, periodic_pressure_, settings_.gradient);
}

std::vector<double> PeriodicFlow::throat_constrictions() const {
  const PeriodicMesh& m = mesh();
  static const BoxWalls no_walls{};
  const Packing packing{m.image_centre, m.image_radius, no_walls, &m.cell.h};
  std::vector<double> radius(mesh_->facets.size());
  for (int f = 0; f < mesh_->facets.size(); ++f)
    radius[f] = throat_constriction(m.mesh, mesh_->facets.vertex[f], packing).radius;
  return radius;
}

double PeriodicFlow::pressure_at(const Vec3& x) const {
  if (!mesh_ || periodic_pressure_.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto where = mesh_->triangulation.locate(x);
  if (where.cell < 0) return std::numeric_limits<double>::quiet_NaN();
  return periodic_pressure_[where.cell] + settings_.gradient.dot(located_centre(where));
}

Vec3 PeriodicFlow::located_centre(const PeriodicTriangulation::Location& where) const {
  return mesh_->cells.power_centre[where.cell] + mesh_->periodic().cell.translation(where.shift);
}

const CellGeometry& PeriodicFlow::cells() const {
  if (!mesh_) throw std::logic_error("PeriodicFlow: no mesh before the first step");
  return mesh_->cells;
}

const std::vector<double>& PeriodicFlow::fluid_volumes() const {
  static const std::vector<double> none;
  return mesh_ ? mesh_->cells.fluid_volume : none;
}

}  // namespace pfv
