// The viscous stability limit of the explicit coupling, 2 / lambda_max of M^-1 V, where V maps
// sphere velocities to fluid forces through the current mesh (viscous_stability.hpp).
//
// A first mesh has no good starting vector, and power iteration from an arbitrary one creeps:
// the dense packings measured need 40 iterations, each a solve and a force evaluation. The Krylov space of those same
// iterations holds a much better estimate: Arnoldi keeps the iterates orthonormal, and the largest Ritz value of the
// small Hessenberg matrix converges to the extreme eigenvalue far faster than the power
// sequence does (thesis-independent textbook fact; Saad, "Numerical methods for large
// eigenvalue problems", ch. 6). Arnoldi rather than Lanczos because V is only nearly symmetric
// (the viscous part of the force cache is not the exact gradient of the volumes). Later meshes
// start from the previous mode, which is already close: a few power iterations suffice there.
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pfv/engine/pore_mesh.hpp"
#include "pfv/engine/viscous_stability.hpp"

namespace pfv {
namespace {

double dot(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double s = 0;
  for (std::size_t k = 0; k < a.size(); ++k) s += a[k].dot(b[k]);
  return s;
}

// Relative change below which the estimate counts as settled.
constexpr double kWarmSettled = 5e-3;  // power iteration from the previous mode
constexpr double kColdSettled = 1e-6;  // Ritz value between two Krylov dimensions
// Relative Arnoldi residual |A y - theta y| / theta of the largest Ritz pair (y of unit norm)
// below which the cold estimate counts as converged. The Ritz value stalls at the 1e-5 level
// long before its change drops below kColdSettled: on the 10 000-sphere benchmark packing
// (30 000 unknowns) the change rule needed 32 operator applications for a relative error of
// 3e-7, this one 22 for 1.3e-5 (against a Krylov solve to 1e-7), each application a solve.
// For a normal operator some eigenvalue lies within the residual of theta, and the error of an
// isolated extreme one is of order residual^2 / gap; the warm start accepts 5e-3 and the guard
// keeps the safety factor time_step_safety on top of either.
constexpr double kColdResidual = 1e-3;
constexpr int kMinKrylov = 8;

}  // namespace

void check_stability_inputs(const FlowEngine& e, const std::vector<double>& mass) {
  // Linearised about the positions of the last step, which the mesh holds once a step on it has
  // succeeded (a forgotten history, reset_history(), does not matter here).
  if (!e.has_mesh() || e.positions().size() != static_cast<std::size_t>(e.mesh().n_spheres))
    throw std::logic_error("the stability limit needs a mesh: run a step first");
  const int n = e.mesh().n_spheres;
  if (static_cast<int>(mass.size()) != n)
    throw std::invalid_argument("one mass per sphere of the mesh is needed (" + std::to_string(n) + " spheres, " +
                                std::to_string(mass.size()) + " masses)");
  for (int k = 0; k < n; ++k)
    if (!std::isfinite(mass[k])) throw std::invalid_argument("mass of sphere " + std::to_string(k) + " is not finite");
}

double volume_probe_step(const FlowEngine& e) {
  double h = 0;
  for (int a = 0; a < 3; ++a) h = std::max(h, e.walls().extent(a));
  return 1e-7 * h;
}

void apply_viscous_operator(const FlowEngine& e, const std::vector<double>& mass, const std::vector<Vec3>& v,
                            std::vector<Vec3>& accel) {
  const int n = e.mesh().n_spheres, nc = e.mesh().n_cells();
  const PressureSystem& system = e.linear_system().system;
  const int nu = system.n_unknowns();
  const double h = volume_probe_step(e);
  std::vector<Vec3> shifted(e.positions()), force, shear;
  std::vector<double> rhs(nu), x, p_cells(nc, 0.0);
  // dV/dt for the velocity v, by central differences (cell volumes are smooth in x).
  for (int u = 0; u < nu; ++u) {
    const int c = system.unknown_cell[u];
    const CellShape& shape = e.pore_mesh().cells.shape[c];
    for (int k = 0; k < 4 - shape.n_walls; ++k) shifted[shape.v[k]] = e.positions()[shape.v[k]] + h * v[shape.v[k]];
    const double plus = cell_volume(shape, shifted, e.walls());
    for (int k = 0; k < 4 - shape.n_walls; ++k) shifted[shape.v[k]] = e.positions()[shape.v[k]] - h * v[shape.v[k]];
    const double minus = cell_volume(shape, shifted, e.walls());
    for (int k = 0; k < 4 - shape.n_walls; ++k) shifted[shape.v[k]] = e.positions()[shape.v[k]];
    rhs[u] = -(plus - minus) / (2 * h);
  }
  e.linear_system().solver->apply_inverse(rhs, x, e.settings.solve_control());
  for (int u = 0; u < nu; ++u) p_cells[system.unknown_cell[u]] = x[u];
  e.pore_mesh().cache.apply(p_cells, force);
  if (e.pore_mesh().shear) e.pore_mesh().shear->add_velocity_forces(v, e.settings.viscosity_of_shear(), force, shear);
  accel.resize(n);
  for (int k = 0; k < n; ++k) accel[k] = mass[k] > 0 ? Vec3(force[k] / mass[k]) : Vec3::Zero();
}

double viscous_stability_limit(const FlowEngine& e, const std::vector<double>& mass, int iterations,
                               std::vector<Vec3>* mode, int* applications) {
  if (applications) *applications = 0;
  check_stability_inputs(e, mass);
  const int n = e.mesh().n_spheres;
  const int nu = e.linear_system().system.n_unknowns();
  if (nu == 0 || !e.linear_system().ready()) return HUGE_VAL;

  // The given mode, else a deterministic start with a component along every moving sphere.
  std::vector<Vec3> v(n, Vec3::Zero());
  double norm2 = 0;
  if (mode && static_cast<int>(mode->size()) == n)
    for (int k = 0; k < n; ++k)
      if (mass[k] > 0 && (*mode)[k].allFinite()) {
        v[k] = (*mode)[k];
        norm2 += v[k].squaredNorm();
      }
  const bool warm = norm2 > 0;
  if (!warm)
    for (int k = 0; k < n; ++k)
      if (mass[k] > 0) {
        v[k] = Vec3(std::sin(1.0 + 3.1 * k), std::cos(2.0 + 1.7 * k), std::sin(0.5 + 2.3 * k));
        norm2 += v[k].squaredNorm();
      }
  if (norm2 == 0) return HUGE_VAL;
  for (Vec3& u : v) u /= std::sqrt(norm2);

  double lambda = 0;
  int applied = 0;
  std::vector<Vec3> w;
  if (warm) {
    for (int it = 0; it < iterations; ++it) {
      apply_viscous_operator(e, mass, v, w);
      ++applied;
      const double previous = lambda;
      lambda = std::sqrt(dot(w, w));  // |M^-1 V v| for |v| = 1
      if (lambda == 0) break;         // no fluid force for any motion: no limit
      v.swap(w);
      for (Vec3& u : v) u /= lambda;
      if (it >= 2 && std::abs(lambda - previous) <= kWarmSettled * lambda) break;
    }
  } else {
    // Arnoldi: q_0 = v, H(i, j) = q_i' A q_j; the Ritz value of largest modulus estimates
    // lambda_max (the eigenvalues of A = M^-1 V are real and <= 0 up to V's slight asymmetry).
    const int m = std::max(1, iterations);
    std::vector<std::vector<Vec3>> q{v};
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m + 1, m);
    Eigen::VectorXcd ritz_vector;
    for (int j = 0; j < m; ++j) {
      apply_viscous_operator(e, mass, q[j], w);
      ++applied;
      for (int pass = 0; pass < 2; ++pass)  // Gram-Schmidt twice: orthogonal to round-off
        for (int i = 0; i <= j; ++i) {
          const double c = dot(q[i], w);
          H(i, j) += c;
          for (int k = 0; k < n; ++k) w[k] -= c * q[i][k];
        }
      H(j + 1, j) = std::sqrt(dot(w, w));
      Eigen::EigenSolver<Eigen::MatrixXd> eig(H.topLeftCorner(j + 1, j + 1));
      int best = 0;
      for (int i = 1; i <= j; ++i)
        if (std::abs(eig.eigenvalues()[i]) > std::abs(eig.eigenvalues()[best])) best = i;
      const double previous = lambda;
      lambda = std::abs(eig.eigenvalues()[best]);
      ritz_vector = eig.eigenvectors().col(best);
      const bool invariant = H(j + 1, j) <= 1e-12 * std::max(lambda, 1e-300);
      // A q_j = sum_i H(i, j) q_i + H(j+1, j) q_{j+1}, so the Ritz pair's residual is
      // H(j+1, j) |last component of its (unit) eigenvector of H|: no extra application.
      const double residual = H(j + 1, j) * std::abs(ritz_vector[j]);
      const bool settled = std::abs(lambda - previous) <= kColdSettled * lambda || residual <= kColdResidual * lambda;
      if (invariant || (j + 1 >= kMinKrylov && settled)) break;
      q.emplace_back(w);
      for (Vec3& u : q.back()) u /= H(j + 1, j);
    }
    // The Ritz vector (real part; the wanted eigenvalue is real up to round-off) as the mode.
    v.assign(n, Vec3::Zero());
    for (int i = 0; i < ritz_vector.size(); ++i)
      for (int k = 0; k < n; ++k) v[k] += ritz_vector[i].real() * q[i][k];
    const double vn = std::sqrt(dot(v, v));
    if (vn > 0)
      for (Vec3& u : v) u /= vn;
  }
  if (applications) *applications = applied;
  if (lambda == 0) return HUGE_VAL;
  if (!std::isfinite(lambda))
    throw std::domain_error(
        "the collective viscous stability limit is not finite (the linearised fluid operator "
        "gave NaN or infinity: check the positions, masses and viscosity)");
  if (mode) *mode = std::move(v);
  return 2.0 / lambda;
}

}  // namespace pfv
