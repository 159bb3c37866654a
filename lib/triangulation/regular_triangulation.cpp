#include "triangulation/regular_triangulation.hpp"

#include "triangulation/cgal_regular.hpp"

#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <numeric>
#include <utility>

namespace pfv {

using namespace cgal_regular;

struct RegularTriangulation::Impl {
  RT rt;
};

RegularTriangulation::RegularTriangulation() : impl_(std::make_unique<Impl>()) {}
RegularTriangulation::~RegularTriangulation() = default;
RegularTriangulation::RegularTriangulation(RegularTriangulation&&) noexcept = default;
RegularTriangulation& RegularTriangulation::operator=(RegularTriangulation&&) noexcept = default;

const Mesh& RegularTriangulation::build(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                        const BoxWalls& walls) {
  const int n = static_cast<int>(centres.size());
  RT& rt = impl_->rt;
  rt.clear();

  Vec3 mid;
  double size = 0;
  for (int a = 0; a < 3; ++a) {
    mid[a] = 0.5 * (walls.coord[2 * a] + walls.coord[2 * a + 1]);
    size = std::max(size, walls.extent(a));
  }
  const double big = kWallRadiusFactor * size;

  std::vector<std::pair<WPoint, int>> points;
  points.reserve(n + kWallCount);
  for (int k = 0; k < n; ++k)
    points.emplace_back(WPoint(K::Point_3(centres[k].x(), centres[k].y(), centres[k].z()), radii[k] * radii[k]), k);
  for (int w = 0; w < kWallCount; ++w) {
    Vec3 c = mid;
    c[wall_axis(w)] = walls.coord[w];
    c -= big * walls.inward_normal(w);
    points.emplace_back(WPoint(K::Point_3(c.x(), c.y(), c.z()), big * big), n + w);
  }
  rt.insert(points.begin(), points.end());  // spatially sorted bulk insertion

  mesh_ = Mesh{};
  mesh_.n_spheres = n;
  walls_ = walls;
  std::vector<char> present(n, 0);
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v)
    if (v->info() < n) present[v->info()] = 1;
  for (int k = 0; k < n; ++k)
    if (!present[k]) mesh_.hidden_spheres.push_back(k);

  // Keep cells with a sphere vertex and no pair of opposite walls (marked kUnnumbered first).
  constexpr int kUnnumbered = -2;
  for (auto c = rt.all_cells_begin(); c != rt.all_cells_end(); ++c) {
    c->info() = -1;
    if (rt.is_infinite(c)) continue;
    int spheres = 0, wall_mask = 0;
    bool opposite = false;
    for (int i = 0; i < 4; ++i) {
      const int v = c->vertex(i)->info();
      if (v < n) {
        ++spheres;
      } else {
        const int w = v - n;
        if (wall_mask & (1 << (w ^ 1))) opposite = true;
        wall_mask |= 1 << w;
      }
    }
    if (spheres == 0 || opposite) continue;
    c->info() = kUnnumbered;
  }
  // Number them breadth-first over their adjacency, each connected group from its first cell in
  // CGAL's storage order. CGAL stores cells in the order its insertion created them, with slots
  // of destroyed cells reused, so that order scatters neighbours across the whole array (on a
  // jittered lattice the mean distance between the numbers of neighbouring unknowns is a tenth of
  // their count). Breadth-first, neighbours lie within one front of each other, and every loop
  // over cells, above all the multigrid solve's sweeps over G, finds the data of neighbouring cells
  // close in memory (mesh.hpp).
  int count = 0;
  std::vector<RT::Cell_handle> front;
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    if (c->info() != kUnnumbered) continue;
    front.clear();
    front.push_back(c);
    c->info() = count++;
    for (std::size_t head = 0; head < front.size(); ++head)
      for (int i = 0; i < 4; ++i) {
        const RT::Cell_handle d = front[head]->neighbor(i);
        if (d->info() != kUnnumbered) continue;
        d->info() = count++;
        front.push_back(d);
      }
  }
  mesh_.cell_vertices.resize(count);
  mesh_.cell_neighbours.resize(count);
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    const int id = c->info();
    if (id < 0) continue;
    for (int i = 0; i < 4; ++i) {
      mesh_.cell_vertices[id][i] = c->vertex(i)->info();
      mesh_.cell_neighbours[id][i] = c->neighbor(i)->info();
    }
  }
  return mesh_;
}

namespace {

// Boundary cells reach the far-away wall spheres; only their part inside the box is a pore.
bool inside(const BoxWalls& walls, const Vec3& x) {
  for (int w = 0; w < kWallCount; ++w)
    if (!(walls.height(w, x) >= 0)) return false;
  return true;
}

}  // namespace

int RegularTriangulation::locate(const Vec3& x) const {
  const RT& rt = impl_->rt;
  if (rt.dimension() < 3 || !inside(walls_, x)) return -1;
  const auto c = rt.locate(WPoint(K::Point_3(x.x(), x.y(), x.z()), 0.0));
  if (rt.is_infinite(c)) return -1;
  return c->info();
}

std::vector<int> RegularTriangulation::locate_all(const std::vector<Vec3>& points) const {
  const RT& rt = impl_->rt;
  const int n = static_cast<int>(points.size());
  std::vector<int> cells(n, -1);
  if (rt.dimension() < 3) return cells;
  std::vector<K::Point_3> p;
  p.reserve(n);
  for (const Vec3& x : points) p.emplace_back(x.x(), x.y(), x.z());
  std::vector<std::size_t> order(n);  // the adapter's key type
  std::iota(order.begin(), order.end(), std::size_t{0});
  using Traits = CGAL::Spatial_sort_traits_adapter_3<K, decltype(CGAL::make_property_map(p))>;
  CGAL::spatial_sort(order.begin(), order.end(), Traits(CGAL::make_property_map(p)));
  RT::Cell_handle hint;  // none: CGAL starts from a cell of its choice
  for (const std::size_t i : order) {
    const Vec3& x = points[i];
    if (!inside(walls_, x)) continue;
    const auto c = rt.locate(WPoint(p[i], 0.0), hint);
    if (rt.is_infinite(c)) continue;
    hint = c;
    cells[i] = c->info();
  }
  return cells;
}

std::vector<std::pair<int, int>> RegularTriangulation::centres_inside_neighbours(
    const std::vector<Vec3>& centres, const std::vector<double>& radii) const {
  std::vector<std::pair<int, int>> bad;
  const RT& rt = impl_->rt;
  const int n = mesh_.n_spheres;
  for (auto e = rt.finite_edges_begin(); e != rt.finite_edges_end(); ++e) {
    const int a = e->first->vertex(e->second)->info();
    const int b = e->first->vertex(e->third)->info();
    if (a >= n || b >= n) continue;
    const double d = (centres[a] - centres[b]).norm();
    if (d < std::max(radii[a], radii[b])) bad.emplace_back(std::min(a, b), std::max(a, b));
  }
  // A hidden sphere has its centre inside the sphere of least power distance from it.
  for (int k : mesh_.hidden_spheres) {
    const Vec3& x = centres[k];
    const auto v = rt.nearest_power_vertex(K::Point_3(x.x(), x.y(), x.z()));
    const int h = v->info();
    if (h < n && (centres[h] - x).norm() < radii[h]) bad.emplace_back(std::min(k, h), std::max(k, h));
  }
  return bad;
}

}  // namespace pfv
