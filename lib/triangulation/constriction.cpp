#include "triangulation/constriction.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <limits>

namespace pfv {

Constriction throat_constriction(const Mesh& mesh, const std::array<int, 3>& facet, const Packing& pk) {
  // Spheres (circles) and walls (lines) of the facet.
  std::array<int, 3> sphere{}, wall{};
  int ns = 0, nw = 0;
  for (int v : facet) {
    if (mesh.is_wall(v))
      wall[nw++] = mesh.wall_of(v);
    else
      sphere[ns++] = v;
  }
  Constriction out;
  if (ns == 0) return out;
  const Vec3& o = pk.centre[sphere[0]];
  // The facet's plane: through the sphere centres and along the normals of its walls.
  Vec3 normal;
  if (nw == 0)
    normal = (pk.centre[sphere[1]] - o).cross(pk.centre[sphere[2]] - o);
  else if (nw == 1)
    normal = (pk.centre[sphere[1]] - o).cross(pk.walls.inward_normal(wall[0]));
  else
    normal = pk.walls.inward_normal(wall[0]).cross(pk.walls.inward_normal(wall[1]));
  const double length = normal.norm();
  if (!(length > 0)) return out;
  normal /= length;
  const Vec3 ex = std::abs(normal.x()) < 0.9 ? Vec3(Vec3::UnitX().cross(normal).normalized())
                                             : Vec3(Vec3::UnitY().cross(normal).normalized());
  const Vec3 ey = normal.cross(ex);
  auto plane = [&](const Vec3& x) { return Eigen::Vector2d((x - o).dot(ex), (x - o).dot(ey)); };

  // Unknowns (X, r), X in the plane. Every line gives h_w(X) = r, every further circle
  // |X - c_i|^2 - (r + r_i)^2 = |X - c_0|^2 - (r + r_0)^2: two linear equations M X + m r = q.
  Eigen::Matrix2d M;
  Eigen::Vector2d m, q;
  const Eigen::Vector2d c0 = plane(o);
  const double r0 = pk.radius[sphere[0]];
  int row = 0;
  for (int i = 1; i < ns; ++i, ++row) {
    const Eigen::Vector2d ci = plane(pk.centre[sphere[i]]);
    const double ri = pk.radius[sphere[i]];
    M.row(row) = 2.0 * (ci - c0).transpose();
    m[row] = 2.0 * (ri - r0);
    q[row] = ci.squaredNorm() - c0.squaredNorm() - (ri * ri - r0 * r0);
  }
  for (int k = 0; k < nw; ++k, ++row) {
    const Vec3 n = pk.walls.inward_normal(wall[k]);
    M.row(row) = Eigen::RowVector2d(n.dot(ex), n.dot(ey));
    m[row] = -1.0;
    q[row] = -pk.walls.height(wall[k], o);
  }
  const Eigen::FullPivLU<Eigen::Matrix2d> lu(M);
  if (!lu.isInvertible()) return out;
  const Eigen::Vector2d u = lu.solve(q), w = lu.solve(-m);  // X = u + r w
  // |u + r w - c_0| = r + r_0: a quadratic in r; the circle in the gap is its smallest positive root.
  const Eigen::Vector2d d = u - c0;
  const double a = w.squaredNorm() - 1.0, b = 2.0 * (w.dot(d) - r0), c = d.squaredNorm() - r0 * r0;
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](double r) {
    if (r > 0 && std::isfinite(r) && r < best) best = r;
  };
  if (std::abs(a) < 1e-14) {
    if (b != 0) consider(-c / b);
  } else {
    const double disc = b * b - 4 * a * c;
    if (disc >= 0) {
      const double s = std::sqrt(disc);
      consider((-b + s) / (2 * a));
      consider((-b - s) / (2 * a));
    }
  }
  if (!std::isfinite(best)) return out;
  const Eigen::Vector2d x = u + best * w;
  out.radius = best;
  out.centre = o + x[0] * ex + x[1] * ey;
  return out;
}

}  // namespace pfv
