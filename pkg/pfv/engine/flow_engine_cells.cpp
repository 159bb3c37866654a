// The members of FlowEngine that act on single cells of the current mesh: the conditions set on
// them and their stored volumes (flow_engine.hpp). Nothing here runs during a step.
#include <cmath>
#include <stdexcept>
#include <string>

#include "pfv/engine/flow_engine.hpp"
#include "pfv/model/cell_queries.hpp"
#include "pfv/snapshot/snapshot.hpp"

namespace pfv {

void FlowEngine::set_cell_imposed(int cell, bool imposed) {
  if (cells_.set_pressure(cell, imposed ? CellPressure::kImposed : CellPressure::kFree, mesh().n_cells()))
    system_rebuild_requested_ = true;
}

void FlowEngine::set_cell_pressure(int cell, double p) {
  if (!std::isfinite(p))
    throw std::invalid_argument("the pressure of cell " + std::to_string(cell) + " must be finite");
  pressure_[cell] = p;
}

void FlowEngine::block_cell(int cell, bool zero_pressure) {
  bool changed = cells_.block(cell, mesh().n_cells());
  changed |= cells_.set_pressure(cell, zero_pressure ? CellPressure::kImposed : CellPressure::kFree, mesh().n_cells());
  if (zero_pressure) pressure_[cell] = 0;
  if (changed) system_rebuild_requested_ = true;
}

std::vector<double> FlowEngine::void_volumes() const {
  if (!measured_void_volume_.empty()) return measured_void_volume_;
  const CellGeometry& g = cells();
  std::vector<double> v(g.volume.size());
  for (std::size_t c = 0; c < v.size(); ++c)
    v[c] = void_volume(g.volume[c], g.fluid_volume[c], settings.minimum_porosity);
  return v;
}

std::vector<double> FlowEngine::volumes_at(const std::vector<Vec3>& centres, const BoxWalls& walls) const {
  if (centres.size() != static_cast<std::size_t>(mesh().n_spheres))
    throw std::invalid_argument("positions of " + std::to_string(centres.size()) + " spheres for a mesh of " +
                                std::to_string(mesh().n_spheres));
  validate_snapshot(centres, std::vector<double>(centres.size(), 1.0), walls);
  const CellGeometry& g = cells();
  std::vector<double> v(g.shape.size());
  for (std::size_t c = 0; c < v.size(); ++c) v[c] = cell_volume(g.shape[c], centres, walls);
  return v;
}

void FlowEngine::initialize_volumes(const std::vector<Vec3>& centres, const BoxWalls& walls) {
  const std::vector<double> now = volumes_at(centres, walls);
  const CellGeometry& g = cells();
  std::vector<double> measured(now.size());
  for (std::size_t c = 0; c < now.size(); ++c)  // the sphere sectors in the cell are those of the mesh
    measured[c] = void_volume(now[c], now[c] - (g.volume[c] - g.fluid_volume[c]), settings.minimum_porosity);
  measured_void_volume_ = std::move(measured);
  if (settings.fluid_bulk_modulus > 0) system_rebuild_requested_ = true;  // the storage changed
  reset_history();
}

void FlowEngine::update_volumes(const std::vector<Vec3>& centres, const BoxWalls& walls, double dt) {
  if (!(dt > 0 && std::isfinite(dt))) throw std::invalid_argument("time step must be positive and finite");
  std::vector<double> now = volumes_at(centres, walls);
  volume_rate_.resize(now.size());
  for (std::size_t c = 0; c < now.size(); ++c) volume_rate_[c] = (now[c] - volume_[c]) / dt;
  volume_ = std::move(now);
  centres_prev_ = centres;
  walls_prev_ = walls;
}

}  // namespace pfv
