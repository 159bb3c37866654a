#include "pfv/engine/remesher.hpp"

#include <chrono>
#include <utility>

#include "pfv/engine/solver_policy.hpp"

namespace pfv {

CellConditions flat_cells(const PoreMesh& m, const EngineSettings& s) {
  CellConditions c;
  if (s.flat_threshold < 0) return c;
  const int n = m.mesh().n_cells();
  for (int k = 0; k < n; ++k)
    if (m.cells.volume[k] <= s.flat_threshold) c.block(k, n);
  return c;
}

Remesher::~Remesher() { wait(); }

bool Remesher::due(const EngineSettings& settings, const PoreMesh* mesh) const {
  return requested_ || !mesh ||
         (settings.mesh_update_interval > 0 && steps_since_remesh_ >= settings.mesh_update_interval) ||
         (settings.def_tolerance > 0 && strain_ >= settings.def_tolerance) || mesh->recipe.stale_for(settings);
}

void Remesher::wait() const {
  if (pending_ && pending_->result.valid()) pending_->result.wait();
}

void Remesher::cancel() {
  wait();  // its snapshot is out of date
  pending_.reset();
}

void Remesher::remesh_in_background(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                    const BoxWalls& walls, const EngineSettings& settings, const BoundaryConditions& bc,
                                    double dt, std::shared_ptr<const CellOrdering> ordering, bool keep_multigrid,
                                    const SolveHistory& history) {
  ++launches_;
  // Snapshot now, build on another thread, carry on with the current mesh meanwhile. The current
  // solver stays in use; an empty multigrid solver stands for it where kAuto keeps that choice
  // (without it the worker would pay the ordering and analysis that decided it again).
  pending_ = Pending{std::async(std::launch::async, [c = centres, r = radii, w = walls, s = settings, b = bc, dt,
                                                     o = std::move(ordering), keep = keep_multigrid, h = history]() {
    PoreMesh m = build_pore_mesh(c, r, w, s);
    CellConditions flat = flat_cells(m, s);
    std::unique_ptr<PressureSolver> recycled = background_stand_in(keep);
    LinearSystem l = build_linear_system(m, b, s, dt, o.get(), std::move(recycled), {&flat}, h);
    return Remesh{std::move(m), std::move(l), std::move(flat)};
  })};
  strain_ = 0;
  steps_since_remesh_ = 0;
}

std::optional<Remesh> Remesher::take_finished() {
  if (!pending_ || pending_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return {};
  auto future = std::move(pending_->result);
  pending_.reset();
  try {
    return future.get();
  } catch (...) {
    requested_ = true;  // the next step remeshes in the foreground and says why
    throw;
  }
}

void Remesher::restart() {
  strain_ = 0;
  steps_since_remesh_ = 0;
  requested_ = false;
}

void Remesher::restore(int steps_since_remesh, double strain) {
  steps_since_remesh_ = steps_since_remesh;
  strain_ = strain;
}

void Remesher::reset() {
  cancel();
  strain_ = 0;
  steps_since_remesh_ = 0;
  requested_ = true;
}

}  // namespace pfv
