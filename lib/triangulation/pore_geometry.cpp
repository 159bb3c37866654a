#include "triangulation/pore_geometry.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pfv/common/parallel.hpp"
#include "triangulation/solid_angle.hpp"

namespace pfv {
namespace {

Vec3 unit_or_zero(const Vec3& v) {
  const double n = v.norm();
  return n > 0 ? Vec3(v / n) : Vec3::Zero();
}

// Power centres of two cells closer than this, relative to their coordinates and the facet's
// size, are one point computed twice: cells of cospherical spheres (a cubic lattice) share
// their centre, which floating point returns with a difference of a few ulps, or none. A
// genuine throat this short would be clamped to the largest conductance all the same.
constexpr double kCoincidentCentres = 1e-10;
// Half-height of the thin bipyramid whose wetted areas stand for those of a zero-length throat,
// relative to the facet's size: the areas are linear in it, their ratios are its limit.
constexpr double kThinThroat = 1e-6;

bool coincident_centres(const Vec3& a, const Vec3& b, double facet_area) {
  const double scale = std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), std::sqrt(facet_area)});
  return (a - b).norm() <= kCoincidentCentres * scale;
}

// A facet seen as a planar polygon: the triangle of three spheres, or its limit when one
// or two vertices are walls (a trapezoid or a rectangle reaching the wall planes).
struct FacetPolygon {
  int n_real = 0;
  std::array<int, 3> real{};  // sphere ids
  std::array<int, 3> slot{};  // position of each sphere in the facet's vertex triple
  int n_walls = 0;
  std::array<int, 3> wall{};  // wall indices
  std::array<int, 3> wall_slot{};
  Vec3 area = Vec3::Zero();                        // unoriented area vector
  std::array<std::array<Vec3, 2>, 3> edge{};       // unit edge directions at each sphere
  std::array<std::array<Vec3, 2>, 3> wall_edge{};  // the polygon's side lying on each wall
};

FacetPolygon make_polygon(const Mesh& mesh, const std::array<int, 3>& v, const Packing& pk) {
  FacetPolygon f;
  for (int i = 0; i < 3; ++i) {
    if (mesh.is_wall(v[i])) {
      f.wall_slot[f.n_walls] = i;
      f.wall[f.n_walls++] = mesh.wall_of(v[i]);
    } else {
      f.slot[f.n_real] = i;
      f.real[f.n_real++] = v[i];
    }
  }
  const BoxWalls& W = pk.walls;
  const auto& c = pk.centre;
  if (f.n_real == 3) {
    const Vec3 &a = c[f.real[0]], &b = c[f.real[1]], &d = c[f.real[2]];
    f.area = 0.5 * (b - a).cross(d - a);
    for (int i = 0; i < 3; ++i) {
      const Vec3& x = c[f.real[i]];
      f.edge[i] = {unit_or_zero(c[f.real[(i + 1) % 3]] - x), unit_or_zero(c[f.real[(i + 2) % 3]] - x)};
    }
  } else if (f.n_real == 2) {
    const int w = f.wall[0];
    const Vec3 &a = c[f.real[0]], &b = c[f.real[1]];
    const Vec3 pa = W.project(w, a), pb = W.project(w, b);
    f.area = 0.5 * (pb - a).cross(pa - b);
    const Vec3 out = -W.inward_normal(w);
    f.edge[0] = {unit_or_zero(b - a), out};
    f.edge[1] = {unit_or_zero(a - b), out};
    f.wall_edge[0] = {pa, pb};
  } else if (f.n_real == 1) {
    const int w1 = f.wall[0], w2 = f.wall[1];
    const Vec3& a = c[f.real[0]];
    const Vec3 p1 = W.project(w1, a), p2 = W.project(w2, a), q = W.project(w2, p1);
    f.area = 0.5 * (q - a).cross(p2 - p1);
    f.edge[0] = {-W.inward_normal(w1), -W.inward_normal(w2)};
    f.wall_edge[0] = {p1, q};
    f.wall_edge[1] = {p2, q};
  }
  return f;
}

// Orientation of a facet away from the cell vertex 'opposite' (a sphere, or a wall whose
// fictitious centre lies at infinity beyond the wall plane).
Vec3 away_from(const Mesh& mesh, const FacetPolygon& f, int opposite, const Packing& pk) {
  if (f.n_real == 0) return Vec3::Zero();
  if (mesh.is_wall(opposite)) return pk.walls.inward_normal(mesh.wall_of(opposite));
  return pk.centre[f.real[0]] - pk.centre[opposite];
}

std::array<int, 3> facet_vertices(const Mesh& mesh, int cell, int local) {
  std::array<int, 3> v{};
  for (int i = 0, k = 0; i < 4; ++i)
    if (i != local) v[k++] = mesh.cell_vertices[cell][i];
  return v;
}

// Power (radical) centre: equal power distance to the spheres, on the planes of the walls.
Vec3 power_centre(const CellShape& s, const Packing& pk) {
  const int n_real = 4 - s.n_walls;
  const Vec3& a = pk.centre[s.v[0]];
  const double ra2 = pk.radius[s.v[0]] * pk.radius[s.v[0]];
  Eigen::Matrix3d m;
  Eigen::Vector3d rhs;
  int row = 0;
  for (int i = 1; i < n_real; ++i, ++row) {
    const Vec3 d = pk.centre[s.v[i]] - a;
    const double r2 = pk.radius[s.v[i]] * pk.radius[s.v[i]];
    m.row(row) = 2.0 * d.transpose();
    rhs[row] = d.squaredNorm() - r2 + ra2;
  }
  for (int i = n_real; i < 4; ++i, ++row) {
    const int w = s.v[i];
    m.row(row) = pk.walls.inward_normal(w).transpose();
    rhs[row] = -pk.walls.height(w, a);
  }
  const Eigen::PartialPivLU<Eigen::Matrix3d> lu(m);
  const double scale = m.cwiseAbs().maxCoeff();
  if (!(std::abs(lu.determinant()) > 1e-12 * scale * scale * scale)) {
    // Flat cell: its power centre is at infinity; the centroid keeps lengths finite.
    Vec3 g = Vec3::Zero();
    for (int i = 0; i < n_real; ++i) g += pk.centre[s.v[i]];
    g /= n_real;
    for (int i = n_real; i < 4; ++i) g = pk.walls.project(s.v[i], g);
    return g;
  }
  return a + lu.solve(rhs);
}

// Unit directions of the three cell edges leaving sphere vertex k of the cell.
std::array<Vec3, 3> edges_from(const CellShape& s, int k, const Packing& pk) {
  const int n_real = 4 - s.n_walls;
  std::array<Vec3, 3> e;
  int m = 0;
  const Vec3& x = pk.centre[s.v[k]];
  for (int i = 0; i < 4; ++i) {
    if (i == k) continue;
    e[m++] = i < n_real ? unit_or_zero(pk.centre[s.v[i]] - x) : Vec3(-pk.walls.inward_normal(s.v[i]));
  }
  return e;
}

}  // namespace

CellShape make_cell_shape(const Mesh& mesh, int cell) {
  CellShape s;
  int walls[4], nw = 0, nr = 0;
  for (int v : mesh.cell_vertices[cell]) {
    if (mesh.is_wall(v))
      walls[nw++] = mesh.wall_of(v);
    else
      s.v[nr++] = v;
  }
  for (int i = 0; i < nw; ++i) s.v[nr + i] = walls[i];
  s.n_walls = static_cast<std::int8_t>(nw);
  return s;
}

double oriented_cell_volume(const CellShape& s, const std::vector<Vec3>& c, const BoxWalls& W) {
  // The heights are positive for centres inside the box (validate_snapshot), so the sign comes
  // from the sphere part alone.
  switch (s.n_walls) {
    case 0: {
      const Vec3& a = c[s.v[0]];
      return (c[s.v[1]] - a).dot((c[s.v[2]] - a).cross(c[s.v[3]] - a)) / 6.0;
    }
    case 1: {  // projected triangle times mean height
      const int w = s.v[3];
      const Vec3 &a = c[s.v[0]], &b = c[s.v[1]], &d = c[s.v[2]];
      const double projected = 0.5 * (b - a).cross(d - a)[wall_axis(w)];
      return projected * (W.height(w, a) + W.height(w, b) + W.height(w, d)) / 3.0;
    }
    case 2: {  // segment swept to the wall edge: |ab . e| * integral of h1 h2 along ab
      const int w1 = s.v[2], w2 = s.v[3];
      const Vec3 &a = c[s.v[0]], &b = c[s.v[1]];
      const int axis = 3 - wall_axis(w1) - wall_axis(w2);
      const double h1a = W.height(w1, a), h1b = W.height(w1, b);
      const double h2a = W.height(w2, a), h2b = W.height(w2, b);
      return (b[axis] - a[axis]) * ((h1a * h2a + h1b * h2b) / 3.0 + (h1a * h2b + h1b * h2a) / 6.0);
    }
    case 3: {
      const Vec3& a = c[s.v[0]];
      return W.height(s.v[1], a) * W.height(s.v[2], a) * W.height(s.v[3], a);
    }
  }
  return 0.0;
}

CellGeometry compute_cell_geometry(const Mesh& mesh, const Packing& pk) {
  const int n = mesh.n_cells();
  CellGeometry g;
  g.shape.resize(n);
  g.volume.resize(n);
  g.fluid_volume.resize(n);
  g.power_centre.resize(n);
#pragma omp parallel for schedule(static) if (n > kMinParallelLoop)
  for (int i = 0; i < n; ++i) {
    CellShape s = make_cell_shape(mesh, i);
    const double oriented = oriented_cell_volume(s, pk.centre, pk.walls);
    s.orientation = static_cast<std::int8_t>((oriented > 0) - (oriented < 0));
    g.shape[i] = s;
    g.volume[i] = std::abs(oriented);
    double solid = 0;
    for (int k = 0; k < 4 - s.n_walls; ++k) {
      const auto e = edges_from(s, k, pk);
      const double r = pk.radius[s.v[k]];
      solid += solid_angle(e[0], e[1], e[2]) * r * r * r / 3.0;
    }
    g.fluid_volume[i] = std::max(0.0, g.volume[i] - solid);
    g.power_centre[i] = power_centre(s, pk);
  }
  return g;
}

Vec3 neighbour_translation(const Mesh& mesh, const Packing& pk, int cell, int local) {
  if (!mesh.periodic() || pk.period == nullptr) return Vec3::Zero();
  const Offset& o = mesh.neighbour_shift[cell][local];
  return *pk.period * Vec3(o[0], o[1], o[2]);
}

Vec3 facet_area_vector(const Mesh& mesh, const std::array<int, 3>& facet, int opposite, const Packing& pk) {
  const FacetPolygon f = make_polygon(mesh, facet, pk);
  const Vec3 dir = away_from(mesh, f, opposite, pk);
  return f.area.dot(dir) < 0 ? Vec3(-f.area) : f.area;
}

FacetGeometry compute_facet_geometry(const Mesh& mesh, const CellGeometry& cells, const Packing& pk,
                                     bool slip_boundary) {
  FacetGeometry g;
  // Each facet once: from its lower-numbered pore cell, or from its only pore cell.
  const bool periodic = mesh.periodic();
  if (periodic && pk.period == nullptr)
    throw std::invalid_argument("compute_facet_geometry: a periodic mesh needs the packing's period");
  for (int i = 0; i < mesh.n_cells(); ++i)
    for (int l = 0; l < 4; ++l) {
      const int j = mesh.cell_neighbours[i][l];
      int lj = -1;
      if (periodic) {
        lj = mesh.cell_mirror[i][l];
      } else if (j >= 0) {
        for (int m = 0; m < 4; ++m)
          if (mesh.cell_neighbours[j][m] == i) lj = m;
      }
      if (j >= 0 && j < i) continue;
      g.cell.push_back({i, j});
      g.local.push_back({l, lj});
      if (periodic) g.translation.push_back(neighbour_translation(mesh, pk, i, l));
    }
  const int nf = g.size();
  g.vertex.resize(nf);
  g.area_vector.resize(nf);
  g.fluid_area.resize(nf);
  g.length.resize(nf);
  g.hydraulic_radius.resize(nf);
  g.sector_area.resize(nf);
  g.wetted_area.resize(nf);

#pragma omp parallel for schedule(static) if (nf > kMinParallelLoop)
  for (int f = 0; f < nf; ++f) {
    const int i = g.cell[f][0], j = g.cell[f][1];
    const auto v = facet_vertices(mesh, i, g.local[f][0]);
    g.vertex[f] = v;
    const FacetPolygon poly = make_polygon(mesh, v, pk);
    const int opposite = mesh.cell_vertices[i][g.local[f][0]];
    Vec3 S = poly.area;
    if (S.dot(away_from(mesh, poly, opposite, pk)) < 0) S = -S;
    g.area_vector[f] = S;
    const double area = S.norm();

    std::array<double, 3> sector{}, wetted{};
    double sectors = 0;
    for (int r = 0; r < poly.n_real; ++r) {
      const double rad = pk.radius[poly.real[r]];
      sector[poly.slot[r]] = 0.5 * planar_angle(poly.edge[r][0], poly.edge[r][1]) * rad * rad;
      sectors += sector[poly.slot[r]];
    }
    // Sectors can exceed the facet where a sphere reaches across it (overlaps, spheres cutting
    // a wall). The facet is then all solid: scale the sectors so that solid + fluid is still the
    // facet area, which keeps every cell a closed surface and the force balance exact.
    if (sectors > area && sectors > 0)
      for (double& a : sector) a *= area / sectors;
    g.sector_area[f] = sector;
    g.fluid_area[f] = std::max(0.0, area - sectors);

    if (poly.n_real == 0 || area <= 0) {
      g.length[f] = 0;
      g.hydraulic_radius[f] = 0;
      g.wetted_area[f] = wetted;
      continue;
    }
    // Signed heights of the two power centres over the facet plane, each positive on its
    // own side: the throat is the bipyramid between them (a difference if on one side).
    const Vec3 nrm = S / area;
    const Vec3& x0 = pk.centre[poly.real[0]];
    const Vec3& Pi = cells.power_centre[i];
    std::array<Vec3, 2> apex{Pi, Pi};
    std::array<double, 2> height{-nrm.dot(Pi - x0), 0.0};
    int sides = 1;
    if (j >= 0) {
      apex[1] = cells.power_centre[j];
      if (periodic) apex[1] += g.translation[f];
      height[1] = nrm.dot(apex[1] - x0);
      sides = 2;
      g.length[f] = (apex[1] - Pi).norm();
      if (coincident_centres(Pi, apex[1], area)) {
        // One pore cut in two by an arbitrary facet (cospherical spheres): its length is 0, and
        // the flat bipyramid between the centres would give phi and gamma as round-off, 0/0, so
        // the wetted areas are those of a thin bipyramid on the centre's foot in the facet.
        g.length[f] = 0;
        const double delta = kThinThroat * std::sqrt(area);
        const Vec3 foot = Pi + height[0] * nrm;
        apex = {foot - delta * nrm, foot + delta * nrm};
        height = {delta, delta};
      }
    } else {
      g.length[f] = 0;
    }
    double volume = 0, solid = 0;
    for (int s = 0; s < sides; ++s) {
      volume += area * height[s] / 3.0;
      const double sign = height[s] >= 0 ? 1.0 : -1.0;
      for (int r = 0; r < poly.n_real; ++r) {
        const Vec3& x = pk.centre[poly.real[r]];
        const double rad = pk.radius[poly.real[r]];
        const Vec3 to_apex = apex[s] - x;
        if (to_apex.squaredNorm() == 0) continue;
        const double om = sign * solid_angle(poly.edge[r][0], poly.edge[r][1], unit_or_zero(to_apex));
        solid += om * rad * rad * rad / 3.0;
        wetted[poly.slot[r]] += om * rad * rad;
      }
      if (!slip_boundary)
        for (int w = 0; w < poly.n_walls; ++w) {
          const auto& e = poly.wall_edge[w];
          wetted[poly.wall_slot[w]] += sign * 0.5 * (e[1] - e[0]).cross(apex[s] - e[0]).norm();
        }
    }
    for (double& x : wetted) x = std::max(0.0, x);
    g.wetted_area[f] = wetted;
    const double phi = volume - solid;
    const double gamma = wetted[0] + wetted[1] + wetted[2];
    g.hydraulic_radius[f] = (phi > 0 && gamma > 0) ? phi / gamma : 0.0;
  }
  return g;
}

int find_facet(const FacetGeometry& g, const Mesh& mesh, int cell, int local) {
  const int other = mesh.cell_neighbours[cell][local];
  // The owner is the lower-numbered cell (or the only one); its facets are contiguous.
  const int owner = other >= 0 && other < cell ? other : cell;
  const auto first = std::lower_bound(g.cell.begin(), g.cell.end(), owner,
                                      [](const std::array<int, 2>& c, int x) { return c[0] < x; });
  for (auto it = first; it != g.cell.end() && (*it)[0] == owner; ++it) {
    const std::size_t f = static_cast<std::size_t>(it - g.cell.begin());
    if ((g.cell[f][0] == cell && g.local[f][0] == local) || (g.cell[f][1] == cell && g.local[f][1] == local))
      return static_cast<int>(f);
  }
  return -1;
}

std::array<double, 3> half_throat_wetted_area(const Mesh& mesh, const CellGeometry& cells, const Packing& pk, int cell,
                                              int local, const std::array<bool, kWallCount>& solid_wall) {
  std::array<double, 3> wetted{};
  const auto v = facet_vertices(mesh, cell, local);
  const FacetPolygon poly = make_polygon(mesh, v, pk);
  const double area = poly.area.norm();
  if (poly.n_real == 0 || area <= 0) return wetted;
  Vec3 S = poly.area;
  if (S.dot(away_from(mesh, poly, mesh.cell_vertices[cell][local], pk)) < 0) S = -S;
  const Vec3& apex = cells.power_centre[cell];
  // The apex lies on the cell's side of the facet unless the height is negative.
  const double sign = -(S / area).dot(apex - pk.centre[poly.real[0]]) >= 0 ? 1.0 : -1.0;
  for (int r = 0; r < poly.n_real; ++r) {
    const Vec3& x = pk.centre[poly.real[r]];
    const double rad = pk.radius[poly.real[r]];
    const Vec3 to_apex = apex - x;
    if (to_apex.squaredNorm() == 0) continue;
    wetted[poly.slot[r]] += sign * solid_angle(poly.edge[r][0], poly.edge[r][1], unit_or_zero(to_apex)) * rad * rad;
  }
  for (int w = 0; w < poly.n_walls; ++w) {
    if (!solid_wall[poly.wall[w]]) continue;
    const auto& e = poly.wall_edge[w];
    wetted[poly.wall_slot[w]] += sign * 0.5 * (e[1] - e[0]).cross(apex - e[0]).norm();
  }
  for (double& x : wetted) x = std::max(0.0, x);
  return wetted;
}

std::array<Vec3, 4> wall_footprints(const Mesh& mesh, int cell, const Packing& pk) {
  std::array<Vec3, 4> out;
  for (int l = 0; l < 4; ++l) {
    out[l] = Vec3::Zero();
    const int v = mesh.cell_vertices[cell][l];
    if (!mesh.is_wall(v)) continue;
    const Vec3 n = pk.walls.inward_normal(mesh.wall_of(v));
    const Vec3 S = facet_area_vector(mesh, facet_vertices(mesh, cell, l), v, pk);
    out[l] = -std::abs(S.dot(n)) * n;
  }
  return out;
}

}  // namespace pfv
