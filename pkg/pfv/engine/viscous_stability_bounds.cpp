// Certified lower bounds on the collective viscous stability limit 2 / lambda_max(A),
// A = M^-1 S G^-1 B (B: sphere velocities to cell volume rates, G: the pressure matrix, S: the
// force cache; viscous_stability.cpp computes the limit itself). A bound that shows the time step
// safe spares the guard the limit's tens of solves. Both rest on G being a Stieltjes matrix
// (symmetric positive definite, off-diagonal entries <= 0): checked, else there is no bound (0).
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "pfv/engine/pore_mesh.hpp"
#include "pfv/engine/viscous_stability.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/refinement.hpp"

namespace pfv {
namespace {

bool stieltjes(const PressureSystem& system) {
  const SymmetricMatrix& g = *system.matrix;
  for (int col = 0; col < g.size(); ++col)
    for (int e = g.col_start[col]; e < g.col_start[col + 1]; ++e)
      if (g.row[e] != col && g.value[e] > 0) return false;
  return true;
}

// d|V_c| / dx of sphere vertex k of a cell (dV/dt differentiates the total volume, unsigned): for
// a tetrahedron a third of the opposite face's area vector, oriented; for a wall prism central
// differences along each coordinate, exact because its volume is at most quadratic in any one.
Vec3 volume_gradient(const CellShape& shape, int k, std::vector<Vec3>& centre, const BoxWalls& walls, double h) {
  if (shape.n_walls == 0) {
    const Vec3& p0 = centre[shape.v[0]];
    const Vec3 e1 = centre[shape.v[1]] - p0, e2 = centre[shape.v[2]] - p0, e3 = centre[shape.v[3]] - p0;
    const Vec3 g1 = e2.cross(e3) / 6, g2 = e3.cross(e1) / 6, g3 = e1.cross(e2) / 6;
    const double sign = e1.dot(g1) < 0 ? -1.0 : 1.0;
    return sign * (k == 0 ? Vec3(-(g1 + g2 + g3)) : k == 1 ? g1 : k == 2 ? g2 : g3);
  }
  Vec3 g;
  Vec3& x = centre[shape.v[k]];
  for (int a = 0; a < 3; ++a) {
    const double x0 = x[a];
    x[a] = x0 + h;
    const double plus = cell_volume(shape, centre, walls);
    x[a] = x0 - h;
    const double minus = cell_volume(shape, centre, walls);
    x[a] = x0;
    g[a] = (plus - minus) / (2 * h);
  }
  return g;
}

}  // namespace

// The global bound, about one solve: every eigenvalue satisfies |lambda| <= ||A||_inf, and G^-1
// is entrywise nonnegative, so
//   ||A||_inf <= max over sphere components (s, a) of (|S| G^-1 beta)_(s,a) / m_s,
// beta_c = sum of |dV_c / dx_(k,b)| over the moving spheres k of cell c and the axes b.
// One solve gives G^-1 beta. It is checked rather than trusted: z counts as an upper bound of
// G^-1 beta only where G z >= beta holds entry by entry (then z - G^-1 beta = G^-1 (G z - beta)
// >= 0), which also covers a reduced-precision factor and an iterative solver. The bound loses
// the cancellations of the true operator (a uniform pressure pushes no interior sphere) and G^-1
// spreads a local source over the drainage path, so it sits up to four orders of magnitude above
// lambda_max on the packings measured: good enough to show a small step safe, never to find the
// limit. The optional shear term is not covered: with it there is no bound.
double viscous_stability_bound(const FlowEngine& e, const std::vector<double>& mass) {
  check_stability_inputs(e, mass);
  if (e.pore_mesh().shear) return 0;
  const PressureSystem& system = e.linear_system().system;
  const int nu = system.n_unknowns();
  if (nu == 0 || !e.linear_system().ready()) return HUGE_VAL;
  if (!stieltjes(system)) return 0;
  const double h = volume_probe_step(e);
  std::vector<double> beta(nu, 0.0);
  std::vector<Vec3> shifted(e.positions());
  double beta_max = 0;
  for (int u = 0; u < nu; ++u) {
    const CellShape& shape = e.pore_mesh().cells.shape[system.unknown_cell[u]];
    for (int k = 0; k < 4 - shape.n_walls; ++k)
      if (mass[shape.v[k]] > 0) beta[u] += volume_gradient(shape, k, shifted, e.walls(), h).cwiseAbs().sum();
    beta_max = std::max(beta_max, beta[u]);
  }
  if (beta_max == 0) return HUGE_VAL;  // nothing moves any pore: no fluid force, no limit
  // A floor keeps every entry of the target positive, so that the check below has room for
  // round-off in cells no moving sphere touches; it only raises the bound, by about 1e-6.
  for (double& b : beta) b += 1e-6 * beta_max;

  // z ~ G^-1 beta, then scaled by q = max beta_u / (G z)_u so that G (q z) >= beta entry by entry.
  // The scaling certifies z whatever its accuracy, and costs the bound a factor of about q, so a
  // conjugate-gradient solver stops at a relative residual of 1e-4, far short of an exact solve,
  // and so does each refinement pass. Gauss-Seidel's stopping rule (the last sweep's change) says nothing of the
  // residual: it keeps the tight tolerance.
  // One substitution of a 32-bit factor leaves q within a few 1e-4 of 1. Should q exceed 1.01, or
  // (G z)_u be <= 0 somewhere, refinement passes improve z; a z they leave with q > 2 gives no bound.
  constexpr double kTolerance = 1e-4;
  constexpr double kGoodScale = 1.01;
  constexpr double kMaxScale = 2;
  constexpr int kMaxPasses = 6;
  std::vector<double> z, correction, defect;
  SolveControl control = e.settings.solve_control();
  const LinearSystem& linear = e.linear_system();
  if (linear.solver->kind() != SolverKind::kGaussSeidel) control.inverse_tolerance = kTolerance;
  linear.solver->apply_inverse(beta, z, control);
  // G's rows where the factor's refinement keeps them, as its residual reads them.
  const MatrixRows none;
  const MatrixRows& g_rows = linear.cholesky() ? linear.cholesky()->rows() : none;
  double q = HUGE_VAL;
  for (int pass = 0; pass < kMaxPasses; ++pass) {
    residual(*system.matrix, g_rows, beta, z, defect);  // beta - G z
    q = 0;
    for (int u = 0; u < nu && q < HUGE_VAL; ++u) {
      const double gz = beta[u] - defect[u];
      q = gz > 0 ? std::max(q, beta[u] / gz) : HUGE_VAL;
    }
    if (q <= kGoodScale) break;
    if (pass + 1 < kMaxPasses) {
      linear.solver->apply_inverse(defect, correction, control);
      for (int u = 0; u < nu; ++u) z[u] += correction[u];
    }
  }
  if (!(q <= kMaxScale)) return 0;  // G is not the matrix this argument needs, or the solve is poor
  std::vector<double> z_cells(e.mesh().n_cells(), 0.0);
  for (int u = 0; u < nu; ++u) z_cells[system.unknown_cell[u]] = std::max(z[u], 0.0) * q;
  std::vector<Vec3> rows;
  e.pore_mesh().cache.apply_magnitude(z_cells, rows);
  double lambda = 0;
  for (int k = 0; k < e.mesh().n_spheres; ++k)
    if (mass[k] > 0) lambda = std::max(lambda, rows[k].maxCoeff() / mass[k]);
  if (!std::isfinite(lambda))
    throw std::domain_error(
        "the bound on the collective viscous stability limit is not finite (check the "
        "positions, masses and viscosity)");
  return lambda > 0 ? 2.0 / lambda : HUGE_VAL;
}

// The local bound, no solve: each throat is a facet with three sphere vertices, so the star
// Laplacians L_s (the terms of G over the facets through sphere s, Dirichlet neighbours included)
// sum to at most 3 G. With B v = sum_s B_s v_s (B_s nonzero on the cells of s only) and F_s = S_s' p,
//   v' B' G^-1 B v = max_p 2 p' B v - p' G p <= sum_s max_p (2 p' B_s v_s - p' L_s p / 3)
//                  = 3 sum_s v_s' B_s' L_s^+ B_s v_s,       |F_s|^2 <= (S_s' L_s^+ S_s) p' L_s p,
// so lambda_max <= ||G^-1/2 B M^-1/2|| ||M^-1/2 S G^-1/2|| <= 3 sqrt(max_s b_s / m_s max_s f_s / m_s),
// b_s and f_s the largest eigenvalues of the 3 x 3 matrices B_s' L_s^+ B_s and S_s' L_s^+ S_s.
// L_s^+ needs both right-hand sides to sum to zero over every part of a star that reaches no
// Dirichlet cell: the star's total volume is fixed by its boundary and a uniform pressure pushes
// no sphere, to round-off; checked (else no bound). The loss is the factor 3 and the local
// problems' closed outer boundary: the bound sits within an order of magnitude of the limit.
double viscous_stability_local_bound(const FlowEngine& e, const std::vector<double>& mass) {
  check_stability_inputs(e, mass);
  if (e.pore_mesh().shear) return 0;
  const PressureSystem& system = e.linear_system().system;
  if (system.n_unknowns() == 0 || !e.linear_system().ready()) return HUGE_VAL;
  if (!stieltjes(system)) return 0;
  const int n = e.mesh().n_spheres, nc = e.mesh().n_cells();
  const CellGeometry& cg = e.pore_mesh().cells;
  const FacetGeometry& fg = e.pore_mesh().facets;
  // Per sphere: its unknown cells (with its local vertex index in each) and the throats through it
  // that carry flow (neither side blocked).
  std::vector<int> cell_start(n + 1, 0), facet_start(n + 1, 0);
  const auto flowing = [&](int f) {
    const int a = fg.cell[f][0], b = fg.cell[f][1];
    return b >= 0 && e.pore_mesh().k[f] != 0 && !system.source[a].is_blocked() && !system.source[b].is_blocked();
  };
  for (int c = 0; c < nc; ++c)
    if (system.unknown[c] >= 0)
      for (int k = 0; k < 4 - cg.shape[c].n_walls; ++k) ++cell_start[cg.shape[c].v[k] + 1];
  for (int f = 0; f < fg.size(); ++f)
    if (flowing(f))
      for (int v : fg.vertex[f])
        if (v < n) ++facet_start[v + 1];
  std::partial_sum(cell_start.begin(), cell_start.end(), cell_start.begin());
  std::partial_sum(facet_start.begin(), facet_start.end(), facet_start.begin());
  std::vector<std::pair<int, int>> star_cell(cell_start[n]);
  std::vector<int> star_facet(facet_start[n]);
  {
    std::vector<int> next(cell_start.begin(), cell_start.end() - 1);
    for (int c = 0; c < nc; ++c)
      if (system.unknown[c] >= 0)
        for (int k = 0; k < 4 - cg.shape[c].n_walls; ++k) star_cell[next[cg.shape[c].v[k]]++] = {c, k};
    next.assign(facet_start.begin(), facet_start.end() - 1);
    for (int f = 0; f < fg.size(); ++f)
      if (flowing(f))
        for (int v : fg.vertex[f])
          if (v < n) star_facet[next[v]++] = f;
  }
  constexpr double kZeroSum = 1e-6;  // relative to the sum of magnitudes, far above round-off
  const double h = volume_probe_step(e);
  std::vector<Vec3> shifted(e.positions());
  std::vector<int> slot(nc, -1), root, part;
  std::vector<char> grounded;
  Eigen::MatrixXd L, rhs;
  double b_max = 0, f_max = 0;
  for (int s = 0; s < n; ++s) {
    const int first = cell_start[s], m = cell_start[s + 1] - first;
    if (!(mass[s] > 0) || m == 0) continue;
    for (int i = 0; i < m; ++i) slot[star_cell[first + i].first] = i;
    const auto release = [&] {
      for (int i = 0; i < m; ++i) slot[star_cell[first + i].first] = -1;
    };
    L.setZero(m, m);
    root.resize(m);
    part.resize(m);
    std::iota(root.begin(), root.end(), 0);
    grounded.assign(m, 0);
    const auto find = [&](int i) {
      while (root[i] != i) i = root[i] = root[root[i]];
      return i;
    };
    for (int j = facet_start[s]; j < facet_start[s + 1]; ++j) {
      const int f = star_facet[j];
      const double kf = e.pore_mesh().k[f];
      const int a = slot[fg.cell[f][0]], b = slot[fg.cell[f][1]];  // -1: a Dirichlet cell
      if (a >= 0) L(a, a) += kf;
      if (b >= 0) L(b, b) += kf;
      if (a >= 0 && b >= 0) {
        L(a, b) -= kf;
        L(b, a) -= kf;
        root[find(a)] = find(b);
      } else if (a >= 0 || b >= 0) {
        grounded[a >= 0 ? a : b] = 1;
      }
    }
    // Columns 0-2: the cells' volume rates per unit velocity of s; 3-5: the force on s per unit pressure.
    rhs.setZero(m, 6);
    for (int i = 0; i < m; ++i) {
      const auto [c, k] = star_cell[first + i];
      rhs.block<1, 3>(i, 0) = volume_gradient(cg.shape[c], k, shifted, e.walls(), h).transpose();
    }
    const auto cells = e.pore_mesh().cache.cells(s);
    const auto units = e.pore_mesh().cache.units(s);
    for (std::size_t k = 0; k < cells.size(); ++k)
      if (system.unknown[cells[k]] >= 0) {
        if (slot[cells[k]] < 0) {  // a force from a cell without s: not the structure assumed
          release();
          return 0;
        }
        rhs.block<1, 3>(slot[cells[k]], 3) += units[k].transpose();
      }
    for (int i = 0; i < m; ++i) {
      part[i] = find(i);
      if (grounded[i]) grounded[part[i]] = 1;
    }
    // On a part that reaches no Dirichlet cell, adding (mu / size) 1 1' changes nothing that L^+
    // does to right-hand sides summing to zero there, and makes the matrix positive definite.
    for (int r = 0; r < m; ++r) {
      if (part[r] != r || grounded[r]) continue;
      int size = 0;
      double diagonal = 0;
      Eigen::Matrix<double, 1, 6> sum = Eigen::Matrix<double, 1, 6>::Zero(), magnitude = sum;
      for (int i = 0; i < m; ++i)
        if (part[i] == r) {
          ++size;
          diagonal += L(i, i);
          sum += rhs.row(i);
          magnitude += rhs.row(i).cwiseAbs();
        }
      for (int a = 0; a < 6; ++a)
        if (std::abs(sum[a]) > kZeroSum * magnitude[a]) {
          release();
          return 0;
        }
      const double shift = (diagonal > 0 ? diagonal : 1.0) / (size * size);
      for (int j = 0; j < m; ++j)
        if (part[j] == r)
          for (int i = 0; i < m; ++i)
            if (part[i] == r) L(i, j) += shift;
    }
    release();
    // With L = C C', r' L^-1 r = |C^-1 r|^2: one triangular solve.
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(L);
    if (llt.info() != Eigen::Success) return 0;
    llt.matrixL().solveInPlace(rhs);
    const Eigen::Matrix<double, 6, 6> k = rhs.transpose() * rhs;
    using Eigen3 = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>;
    const auto largest = [](const Eigen::Matrix3d& a) {
      return Eigen3().computeDirect(a, Eigen::EigenvaluesOnly).eigenvalues()[2];
    };
    b_max = std::max(b_max, largest(k.topLeftCorner<3, 3>()) / mass[s]);
    f_max = std::max(f_max, largest(k.bottomRightCorner<3, 3>()) / mass[s]);
  }
  const double lambda = 3 * std::sqrt(b_max * f_max);
  if (!std::isfinite(lambda))
    throw std::domain_error(
        "the local bound on the collective viscous stability limit is not finite (check the positions, masses "
        "and viscosity)");
  return lambda > 0 ? 2.0 / lambda : HUGE_VAL;
}

}  // namespace pfv
