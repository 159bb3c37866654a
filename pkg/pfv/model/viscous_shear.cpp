#include "pfv/model/viscous_shear.hpp"

#include <cstdint>
#include <utility>

namespace pfv {
namespace {

// Bit of the edge joining local vertices i and j of a cell (i != j): 6 edges, 6 bits.
int edge_bit(int i, int j) {
  if (i > j) std::swap(i, j);
  static constexpr int kIndex[4][4] = {{-1, 0, 1, 2}, {0, -1, 3, 4}, {1, 3, -1, 5}, {2, 4, 5, -1}};
  return 1 << kIndex[i][j];
}

int local_of(const Mesh& mesh, int cell, int v) {
  for (int l = 0; l < 4; ++l)
    if (mesh.cell_vertices[cell][l] == v) return l;
  return -1;
}

// The cells around edge (va, vb) in ring order, starting at 'start' and leaving it across
// the facet opposite 'cross'; 'keep' is the cell's fourth vertex. Each cell is left across
// the facet that contains the edge and the vertex the previous cell did not share, which
// turns around the edge. Returns false if the ring meets a non-pore cell before closing.
bool walk_ring(const Mesh& mesh, int va, int vb, int start, int cross, int keep, std::vector<int>& ring,
               std::vector<int>& exit_local) {
  ring.clear();
  exit_local.clear();
  int cur = start;
  while (static_cast<int>(ring.size()) <= mesh.n_cells()) {
    const int l = local_of(mesh, cur, cross);
    ring.push_back(cur);
    exit_local.push_back(l);
    const int next = mesh.cell_neighbours[cur][l];
    if (next < 0) return false;
    if (next == start) return true;
    int z = -1;
    for (int v : mesh.cell_vertices[next])
      if (v != va && v != vb && v != keep) z = v;
    cross = keep;
    keep = z;
    cur = next;
  }
  return false;  // not reached on a valid mesh
}

}  // namespace

ViscousShear build_viscous_shear(const Mesh& mesh, const CellGeometry& cells, const FacetGeometry& facets,
                                 const Packing& pk, bool include_walls) {
  const int nc = mesh.n_cells();
  std::vector<std::array<int, 4>> facet_of(nc, {-1, -1, -1, -1});
  for (int f = 0; f < facets.size(); ++f)
    for (int side = 0; side < 2; ++side)
      if (facets.cell[f][side] >= 0) facet_of[facets.cell[f][side]][facets.local[f][side]] = f;

  ViscousShear s;
  std::vector<std::uint8_t> done(nc, 0);  // edges of each cell whose ring has been walked
  std::vector<int> ring, exit_local;
  for (int c = 0; c < nc; ++c)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        if (done[c] & edge_bit(i, j)) continue;
        int va = mesh.cell_vertices[c][i], vb = mesh.cell_vertices[c][j];
        if (mesh.is_wall(va)) std::swap(va, vb);
        if (mesh.is_wall(va) || (mesh.is_wall(vb) && !include_walls)) continue;  // no ring walked: no marks needed
        int other[2], k = 0;
        for (int l = 0; l < 4; ++l)
          if (l != i && l != j) other[k++] = mesh.cell_vertices[c][l];
        const bool closed = walk_ring(mesh, va, vb, c, other[0], other[1], ring, exit_local);
        for (int r : ring) done[r] |= edge_bit(local_of(mesh, r, va), local_of(mesh, r, vb));
        if (!closed) {
          // Mark the rest of the ring, walking the other way, so that it is counted once.
          walk_ring(mesh, va, vb, c, other[1], other[0], ring, exit_local);
          for (int r : ring) done[r] |= edge_bit(local_of(mesh, r, va), local_of(mesh, r, vb));
          ++s.open_rings;
          continue;
        }

        const Vec3 dir = mesh.is_wall(vb) ? Vec3(-pk.walls.inward_normal(mesh.wall_of(vb)))
                                          : Vec3((pk.centre[vb] - pk.centre[va]).normalized());
        // The dual facet is planar and normal to the edge; projecting on the edge keeps its
        // area exact when round-off (or a flat cell's fallback centre) moves a vertex off the plane.
        const Vec3& o = cells.power_centre[ring[0]];
        Vec3 twice_area = Vec3::Zero();
        for (std::size_t r = 1; r + 1 < ring.size(); ++r)
          twice_area += (cells.power_centre[ring[r]] - o).cross(cells.power_centre[ring[r + 1]] - o);
        const double area = 0.5 * std::abs(twice_area.dot(dir));

        double fluid = 0, wetted = 0;
        for (std::size_t r = 0; r < ring.size(); ++r) {
          const int f = facet_of[ring[r]][exit_local[r]];
          const auto& w = facets.wetted_area[f];
          const double g = w[0] + w[1] + w[2];
          fluid += facets.hydraulic_radius[f] * g;  // phi of the throat (3.5)
          wetted += g;
        }
        const double rh = (fluid > 0 && wetted > 0) ? fluid / wetted : 0.0;

        // Facets of round-off size (cospherical groups: all power centres coincide) and pairs
        // with no fluid around them would carry no force: not stored.
        const double scale = mesh.is_wall(vb) ? pk.walls.height(mesh.wall_of(vb), pk.centre[va])
                                              : (pk.centre[vb] - pk.centre[va]).norm();
        if (!(area > 1e-13 * scale * scale) || !(rh > 0)) continue;
        s.a.push_back(va);
        s.b.push_back(vb);
        s.direction.push_back(dir);
        s.area.push_back(area);
        s.hydraulic_radius.push_back(rh);
      }
  return s;
}

template <class Velocity>
void ViscousShear::accumulate(const Velocity& velocity, int n_spheres, double viscosity, std::vector<Vec3>& force,
                              std::vector<Vec3>& shear) const {
  // One serial pass: each pair writes two vertices, and the loop costs less than waking threads
  // would on the sizes measured (doc/benchmarks.md).
  shear.assign(force.size(), Vec3::Zero());
  for (int e = 0; e < size(); ++e) {
    const int i = a[e], j = b[e];
    // Walls do not move along their plane, and the normal part is projected out below.
    const Vec3 dv = (j < n_spheres ? velocity(j) : Vec3(Vec3::Zero())) - velocity(i);
    const Vec3& d = direction[e];
    const Vec3 f = (viscosity * area[e] / hydraulic_radius[e]) * (dv - dv.dot(d) * d);
    shear[i] += f;  // i is dragged along by j's relative tangential motion
    shear[j] -= f;
  }
  for (std::size_t v = 0; v < force.size(); ++v) force[v] += shear[v];
}

void ViscousShear::add_forces(const std::vector<Vec3>& x, const std::vector<Vec3>& x_prev, double dt, double viscosity,
                              std::vector<Vec3>& force, std::vector<Vec3>& shear) const {
  accumulate([&](int k) { return Vec3((x[k] - x_prev[k]) / dt); }, static_cast<int>(x.size()), viscosity, force, shear);
}

void ViscousShear::add_velocity_forces(const std::vector<Vec3>& velocity, double viscosity, std::vector<Vec3>& force,
                                       std::vector<Vec3>& shear) const {
  accumulate([&](int k) { return velocity[k]; }, static_cast<int>(velocity.size()), viscosity, force, shear);
}

}  // namespace pfv
