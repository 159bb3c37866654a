#include "triangulation/periodic_triangulation.hpp"

#include "triangulation/cgal_regular.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace pfv {

using namespace cgal_regular;

namespace {

// A sphere translated by whole periods: the vertices of the infinite periodic triangulation.
struct Image {
  int sphere = 0;
  Offset offset{};
  bool operator==(const Image& o) const { return sphere == o.sphere && offset == o.offset; }
  bool operator<(const Image& o) const { return sphere != o.sphere ? sphere < o.sphere : offset < o.offset; }
  Image shifted(const Offset& t) const { return {sphere, {offset[0] - t[0], offset[1] - t[1], offset[2] - t[2]}}; }
};

std::size_t hash_image(const Image& v) {
  std::size_t h = static_cast<std::size_t>(v.sphere) * 0x9E3779B97F4A7C15ULL;
  for (int a = 0; a < 3; ++a) h = (h ^ static_cast<std::size_t>(v.offset[a] + 1024)) * 0x100000001B3ULL;
  return h;
}
struct ImageHash {
  std::size_t operator()(const Image& v) const { return hash_image(v); }
};

// A class of cells up to translation: its vertices sorted, the smallest at offset 0.
using CellKey = std::array<Image, 4>;
struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const {
    std::size_t h = 0;
    for (const Image& v : k) h = (h ^ hash_image(v)) * 0x100000001B3ULL + 0x9E37;
    return h;
  }
};

constexpr int kNotKept = -1;

// The grid the triangulation's input is rounded to: a power of two 2^-50 of the largest
// coordinate an image can have, so that a sphere's wrapped centre plus any lattice translation of
// the rounded cell is exact in double. Every image of a pore is then the exact translate of the
// others, and CGAL's symbolic perturbation (which orders points lexicographically, an order
// translations keep) splits cospherical pores (regular arrays) the same way in every period;
// rounded translations would split them differently and no consistent triangulation would exist.
// The rounding moves points by 1e-15 of the cell. (The wrapped centres lie in the cell, and the
// images within kMaxMarginWidths widths of it.)
double grid_step(const PeriodicCell& cell) {
  const double periods = std::ceil(PeriodicTriangulation::kMaxMarginWidths *
                                   std::max({cell.width(0), cell.width(1), cell.width(2)}) / cell.min_width());
  const double bound = (periods + 3) * cell.h.cwiseAbs().rowwise().sum().maxCoeff();
  return std::ldexp(1.0, std::ilogb(bound) + 1 - 50);
}

template <class M>
M snap(const M& x, double grid) {
  return (x / grid).array().round().matrix() * grid;
}

}  // namespace

struct PeriodicTriangulation::Impl {
  RT rt;
  std::vector<Image> point_image;                             // per inserted point (the vertex info)
  std::vector<RT::Cell_handle> kept;                          // per kept cell, before the renumbering
  std::unordered_map<CellKey, int, CellKeyHash> key_to_cell;  // kept cells, final numbers
  std::vector<Vec3> wrapped;                                  // the centres wrapped into the cell
  std::vector<Offset> wrap;                                   // by these periods
  std::vector<Vec3> fractional;
  PeriodicCell cell;
  Eigen::Matrix3d h_inverse;
  double max_weight = 0;

  std::array<Image, 4> images_of(RT::Cell_handle c) const {
    std::array<Image, 4> v;
    for (int i = 0; i < 4; ++i) v[i] = point_image[c->vertex(i)->info()];
    return v;
  }
  // The translation taking c to its class's representative, and the representative's key.
  static std::pair<Offset, CellKey> canonical(const std::array<Image, 4>& v) {
    const Image least = *std::min_element(v.begin(), v.end());
    CellKey key;
    for (int i = 0; i < 4; ++i) key[i] = v[i].shifted(least.offset);
    std::sort(key.begin(), key.end());
    return {least.offset, key};
  }
  Vec3 position(const Image& v) const { return wrapped[v.sphere] + cell.translation(v.offset); }
};

PeriodicTriangulation::PeriodicTriangulation() : impl_(std::make_unique<Impl>()) {}
PeriodicTriangulation::~PeriodicTriangulation() = default;
PeriodicTriangulation::PeriodicTriangulation(PeriodicTriangulation&&) noexcept = default;
PeriodicTriangulation& PeriodicTriangulation::operator=(PeriodicTriangulation&&) noexcept = default;

const PeriodicMesh& PeriodicTriangulation::build(const std::vector<Vec3>& centres, const std::vector<double>& radii,
                                                 const PeriodicCell& cell) {
  const int n = static_cast<int>(centres.size());
  if (n == 0) throw std::invalid_argument("periodic triangulation: no spheres");
  if (radii.size() != centres.size())
    throw std::invalid_argument("periodic triangulation: " + std::to_string(radii.size()) + " radii for " +
                                std::to_string(n) + " centres");
  if (!cell.h.allFinite() || !(cell.volume() > 0) || !(cell.min_width() > 0))
    throw std::invalid_argument("periodic triangulation: the cell matrix is degenerate or not finite");
  Impl& m = *impl_;
  for (int k = 0; k < n; ++k)
    if (!centres[k].allFinite() || !(radii[k] > 0) || !std::isfinite(radii[k]))
      throw std::invalid_argument("periodic triangulation: sphere " + std::to_string(k) +
                                  " has a non-finite centre or a radius that is not positive");
  const double grid = grid_step(cell);
  m.cell = PeriodicCell{snap(cell.h, grid)};
  m.h_inverse = m.cell.h.inverse();
  m.wrapped.resize(n);
  m.wrap.resize(n);
  m.fractional.resize(n);
  double r_max = 0;
  for (int k = 0; k < n; ++k) {
    const Vec3 f = m.h_inverse * centres[k];
    for (int a = 0; a < 3; ++a) m.wrap[k][a] = -static_cast<int>(std::floor(f[a]));
    // The wrapped centre is the centre moved by whole periods (not h times the fractional
    // part): the same translation at every step, so the images follow the spheres exactly.
    m.wrapped[k] = snap(Vec3(centres[k] + cell.translation(m.wrap[k])), grid);
    m.fractional[k] = m.h_inverse * m.wrapped[k];
    r_max = std::max(r_max, radii[k]);
  }
  m.max_weight = r_max * r_max;
  // A first margin that holds the orthogonal spheres of a dense packing (about twice the
  // largest radius from a centre, so two radii from the cell's faces) with room to spare.
  const double spacing = std::cbrt(cell.volume() / n);
  double margin = std::max(4.0 * r_max, 1.5 * spacing);
  const double limit = kMaxMarginWidths * std::max({cell.width(0), cell.width(1), cell.width(2)});
  for (;;) {
    if (try_build(radii, margin)) return mesh_;
    if (margin >= limit)
      throw std::runtime_error("periodic triangulation: no consistent triangulation with images up to " +
                               std::to_string(margin) + " beyond the cell (" + std::to_string(n) +
                               " spheres; is the cell far larger than the packing's spacing?)");
    margin = std::min(limit, margin * kMarginGrowth);
  }
}

bool PeriodicTriangulation::try_build(const std::vector<double>& radii, double margin) {
  Impl& m = *impl_;
  const PeriodicCell& cell = m.cell;
  const int n = static_cast<int>(m.wrapped.size());
  std::array<double, 3> width{}, reach{};
  std::array<int, 3> periods{};
  for (int a = 0; a < 3; ++a) {
    width[a] = cell.width(a);
    reach[a] = margin / width[a];  // the margin in fractional units along cell vector a
    periods[a] = static_cast<int>(std::ceil(reach[a]));
  }

  // Every image whose fractional coordinates lie within the margin of [0, 1)^3.
  m.point_image.clear();
  std::vector<std::pair<WPoint, int>> points;
  for (int s = 0; s < n; ++s) {
    const Vec3& f = m.fractional[s];
    for (int i = -periods[0]; i <= periods[0]; ++i)
      for (int j = -periods[1]; j <= periods[1]; ++j)
        for (int k = -periods[2]; k <= periods[2]; ++k) {
          const Offset o{i, j, k};
          bool in = true;
          for (int a = 0; a < 3 && in; ++a) in = f[a] + o[a] >= -reach[a] && f[a] + o[a] <= 1.0 + reach[a];
          if (!in) continue;
          const Vec3 x = m.wrapped[s] + cell.translation(o);
          points.emplace_back(WPoint(K::Point_3(x.x(), x.y(), x.z()), radii[s] * radii[s]),
                              static_cast<int>(m.point_image.size()));
          m.point_image.push_back({s, o});
        }
  }
  RT& rt = m.rt;
  rt.clear();
  rt.insert(points.begin(), points.end());
  points = {};
  if (rt.dimension() < 3) return false;

  // The representatives: cells whose smallest vertex is a sphere of the cell itself. Each must
  // be a cell of the infinite triangulation: its orthogonal sphere, grown by the largest weight
  // (the farthest any point's power can reach into it), inside the images' region.
  m.kept.clear();
  m.key_to_cell.clear();
  double volume = 0;
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c) {
    c->info() = kNotKept;
    const auto v = m.images_of(c);
    const auto [shift, key] = Impl::canonical(v);
    if (shift != Offset{0, 0, 0}) continue;
    std::array<Vec3, 4> x;
    for (int i = 0; i < 4; ++i) x[i] = m.position(v[i]);
    Eigen::Matrix3d a;
    Vec3 b;
    for (int i = 1; i < 4; ++i) {
      const Vec3 q = x[i] - x[0];
      a.row(i - 1) = 2.0 * q.transpose();
      b[i - 1] = q.squaredNorm() - radii[v[i].sphere] * radii[v[i].sphere] + radii[v[0].sphere] * radii[v[0].sphere];
    }
    volume += std::abs(a.determinant()) / 48.0;  // det(2q) = 8 det(q), a tetrahedron is det(q) / 6
    const Vec3 y = a.fullPivLu().solve(b);
    if (y.allFinite()) {  // a flat cell has no orthogonal sphere; its neighbours' share its vertices
      const double r2 = y.squaredNorm() - radii[v[0].sphere] * radii[v[0].sphere];
      const double grown = std::sqrt(std::max(r2, 0.0) + m.max_weight);
      const Vec3 fc = m.h_inverse * (x[0] + y);
      for (int k = 0; k < 3; ++k)
        if (fc[k] * width[k] - grown < -margin || fc[k] * width[k] + grown > width[k] + margin) return false;
    }
    c->info() = static_cast<int>(m.kept.size());
    m.key_to_cell.emplace(key, c->info());
    m.kept.push_back(c);
  }
  // All classes kept: the representatives tile one cell.
  if (std::abs(volume - cell.volume()) > 1e-9 * cell.volume()) return false;

  // Neighbours, in the numbering of m.kept: the representative of the cell across each facet.
  const int nc = static_cast<int>(m.kept.size());
  std::vector<std::array<int, 4>> neighbour(nc), mirror(nc);
  std::vector<std::array<Offset, 4>> shift(nc);
  for (int id = 0; id < nc; ++id) {
    const RT::Cell_handle c = m.kept[id];
    for (int l = 0; l < 4; ++l) {
      const RT::Cell_handle d = c->neighbor(l);
      if (rt.is_infinite(d)) return false;
      const auto v = m.images_of(d);
      const auto [t, key] = Impl::canonical(v);
      const auto found = m.key_to_cell.find(key);
      if (found == m.key_to_cell.end()) return false;
      const int j = found->second;
      const Image back = m.point_image[d->vertex(d->index(c))->info()].shifted(t);
      const auto vj = m.images_of(m.kept[j]);
      const int lj = static_cast<int>(std::find(vj.begin(), vj.end(), back) - vj.begin());
      if (lj == 4) return false;
      neighbour[id][l] = j;
      mirror[id][l] = lj;
      shift[id][l] = t;
    }
  }

  // Number the cells breadth-first over their adjacency (as the walled mesh, mesh.hpp).
  std::vector<int> number(nc, -1), order;
  order.reserve(nc);
  for (int start = 0; start < nc; ++start) {
    if (number[start] >= 0) continue;
    number[start] = static_cast<int>(order.size());
    order.push_back(start);
    for (std::size_t head = order.size() - 1; head < order.size(); ++head)
      for (int l = 0; l < 4; ++l) {
        const int j = neighbour[order[head]][l];
        if (number[j] >= 0) continue;
        number[j] = static_cast<int>(order.size());
        order.push_back(j);
      }
  }

  PeriodicMesh out;
  out.n_spheres = n;
  out.wrap = m.wrap;
  out.cell = cell;
  out.margin = margin;
  std::unordered_map<Image, int, ImageHash> image_index;
  auto add_image = [&](const Image& v) {
    const auto [it, added] = image_index.emplace(v, static_cast<int>(out.image_sphere.size()));
    if (added) {
      out.image_sphere.push_back(v.sphere);
      out.image_offset.push_back(v.offset);
      out.image_centre.push_back(m.position(v));
      out.image_radius.push_back(radii[v.sphere]);
    }
    return it->second;
  };
  for (int s = 0; s < n; ++s) add_image({s, {0, 0, 0}});
  out.mesh.cell_vertices.resize(nc);
  out.mesh.cell_neighbours.resize(nc);
  out.mesh.cell_mirror.resize(nc);
  out.mesh.neighbour_shift.resize(nc);
  for (int id = 0; id < nc; ++id) {
    const int i = number[id];
    const auto v = m.images_of(m.kept[id]);
    for (int l = 0; l < 4; ++l) {
      out.mesh.cell_vertices[i][l] = add_image(v[l]);
      out.mesh.cell_neighbours[i][l] = number[neighbour[id][l]];
      out.mesh.cell_mirror[i][l] = mirror[id][l];
      out.mesh.neighbour_shift[i][l] = shift[id][l];
    }
  }
  for (auto& [key, id] : m.key_to_cell) id = number[id];
  for (auto c = rt.finite_cells_begin(); c != rt.finite_cells_end(); ++c)
    if (c->info() != kNotKept) c->info() = number[c->info()];
  std::vector<char> present(n, 0);
  for (auto v = rt.finite_vertices_begin(); v != rt.finite_vertices_end(); ++v) {
    const Image& im = m.point_image[v->info()];
    if (im.offset == Offset{0, 0, 0}) present[im.sphere] = 1;
  }
  for (int s = 0; s < n; ++s)
    if (!present[s]) out.mesh.hidden_spheres.push_back(s);
  out.mesh.n_spheres = out.n_images();
  mesh_ = std::move(out);
  return true;
}

PeriodicTriangulation::Location PeriodicTriangulation::locate(const Vec3& x) const {
  const Impl& m = *impl_;
  Location out;
  if (mesh_.n_cells() == 0 || !x.allFinite()) return out;
  Vec3 f = m.h_inverse * x;
  Offset base{};
  for (int a = 0; a < 3; ++a) {
    base[a] = static_cast<int>(std::floor(f[a]));
    f[a] -= base[a];
  }
  const Vec3 y = m.cell.h * f;
  const auto c = m.rt.locate(WPoint(K::Point_3(y.x(), y.y(), y.z()), 0.0));
  if (m.rt.is_infinite(c)) return out;
  const auto [t, key] = Impl::canonical(m.images_of(c));
  const auto found = m.key_to_cell.find(key);
  if (found == m.key_to_cell.end()) return out;
  out.cell = found->second;
  for (int a = 0; a < 3; ++a) out.shift[a] = base[a] + t[a];
  return out;
}

}  // namespace pfv
