#include "triangulation/power_cells.hpp"

#include <algorithm>
#include <cmath>

namespace pfv {
namespace {

int local_of(const Mesh& mesh, int cell, int v) {
  for (int l = 0; l < 4; ++l)
    if (mesh.cell_vertices[cell][l] == v) return l;
  return -1;
}

// The other two vertices of 'cell' than the edge (a, b).
std::array<int, 2> others(const Mesh& mesh, int cell, int a, int b) {
  std::array<int, 2> o{};
  int k = 0;
  for (int v : mesh.cell_vertices[cell])
    if (v != a && v != b) o[k++] = v;
  return o;
}

// The ring of cells around edge (a, b) starting at 'start', by crossing the facet opposite
// 'leave' first: the cells in order and whether the ring closes.
bool ring(const Mesh& mesh, int start, int a, int b, int leave, std::vector<int>& out) {
  out.assign(1, start);
  int cell = start;
  for (int guard = 0; guard < 1000; ++guard) {
    const auto o = others(mesh, cell, a, b);
    const int stay = o[0] == leave ? o[1] : o[0];
    const int next = mesh.cell_neighbours[cell][local_of(mesh, cell, leave)];
    if (next < 0) return false;
    if (next == start) return true;
    out.push_back(next);
    cell = next;
    leave = stay;  // the facet (a, b, leave) was crossed; next cross the one opposite 'stay'
  }
  return false;
}

}  // namespace

PowerCellVolumes power_cell_volumes(const Mesh& mesh, const CellGeometry& cells, const Packing& pk) {
  PowerCellVolumes out;
  out.volume.assign(mesh.n_spheres, 0.0);
  std::vector<char> incomplete(mesh.n_spheres, 0);
  std::vector<int> cycle, back;
  for (int c = 0; c < mesh.n_cells(); ++c) {
    const auto& cv = mesh.cell_vertices[c];
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        const int a = std::min(cv[i], cv[j]), b = std::max(cv[i], cv[j]);
        if (mesh.is_wall(a)) continue;  // wall-wall edges bound no sphere
        const auto o = others(mesh, c, a, b);
        bool closed = ring(mesh, c, a, b, o[0], cycle);
        // Each edge once: from the lowest-numbered cell of its ring.
        if (*std::min_element(cycle.begin(), cycle.end()) < c) continue;
        if (!closed) {  // open: the rest of the chain lies the other way round
          ring(mesh, c, a, b, o[1], back);
          if (*std::min_element(back.begin(), back.end()) < c) continue;
          cycle.insert(cycle.begin(), back.rbegin(), back.rend() - 1);
        }
        // The face: the polygon of the power centres, its area along the edge.
        const Vec3& p0 = cells.power_centre[cycle[0]];
        Vec3 area = Vec3::Zero();
        for (std::size_t k = 1; k + 1 < cycle.size(); ++k)
          area += 0.5 * (cells.power_centre[cycle[k]] - p0).cross(cells.power_centre[cycle[k + 1]] - p0);
        const Vec3& xa = pk.centre[a];
        if (mesh.is_wall(b)) {
          const int w = mesh.wall_of(b);
          const double face = std::abs(area.dot(pk.walls.inward_normal(w)));
          out.volume[a] += pk.walls.height(w, xa) * face / 3.0;
        } else {
          const Vec3 e = pk.centre[b] - xa;
          const double d = e.norm();
          if (!(d > 0)) continue;
          const double face = std::abs(area.dot(e / d));
          const double ra = pk.radius[a], rb = pk.radius[b];
          const double ha = (d * d + ra * ra - rb * rb) / (2 * d);  // from a to the radical plane
          out.volume[a] += ha * face / 3.0;
          out.volume[b] += (d - ha) * face / 3.0;
          if (!closed) incomplete[b] = 1;
        }
        if (!closed) incomplete[a] = 1;
      }
  }
  for (int s = 0; s < mesh.n_spheres; ++s)
    if (incomplete[s]) out.incomplete.push_back(s);
  return out;
}

}  // namespace pfv
