// PFV's V-cycle over a given hierarchy (amg_cycle.hpp): symmetric and positive, as conjugate
// gradients needs, for each smoother; the same bits on one thread as on a team of two; the exact
// inverse where the hierarchy is one small level; and inconsistent levels refused. The hierarchy
// is built here by aggregation of 2 x 2 x 2 cells of a lattice whose conductances span three
// decades, with Galerkin coarse levels, so that no hypre is needed.
#include <gtest/gtest.h>

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <random>
#include <vector>

#include "pfv/common/parallel.hpp"
#include "pfv/linalg/amg_cycle.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace pfv;

namespace {

using Sparse = Eigen::SparseMatrix<double, Eigen::RowMajor>;

CsrRows rows_of(const Sparse& m) {
  CsrRows r;
  r.n_rows = static_cast<int>(m.rows());
  r.n_cols = static_cast<int>(m.cols());
  r.start.assign(m.outerIndexPtr(), m.outerIndexPtr() + m.rows() + 1);
  r.column.assign(m.innerIndexPtr(), m.innerIndexPtr() + m.nonZeros());
  r.value.assign(m.valuePtr(), m.valuePtr() + m.nonZeros());
  return r;
}

// A 7-point operator on an m^3 lattice, random conductances over three decades, a Dirichlet
// coupling on two faces (positive definite).
Sparse lattice_operator(int m, unsigned seed) {
  const auto id = [m](int i, int j, int k) { return (i * m + j) * m + k; };
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k) {
        const int a = id(i, j, k);
        if (j == 0 || j == m - 1) t.emplace_back(a, a, 1.0);
        for (const auto& [p, q, r] : {std::array{i + 1, j, k}, std::array{i, j + 1, k}, std::array{i, j, k + 1}}) {
          if (p >= m || q >= m || r >= m) continue;
          const int c = id(p, q, r);
          const double g = std::pow(10.0, u(gen));
          t.emplace_back(a, c, -g);
          t.emplace_back(c, a, -g);
          t.emplace_back(a, a, g);
          t.emplace_back(c, c, g);
        }
      }
  Sparse a(m * m * m, m * m * m);
  a.setFromTriplets(t.begin(), t.end());
  return a;
}

// Piecewise constant interpolation from the aggregates of 2 x 2 x 2 cells of an m^3 lattice.
Sparse aggregation(int m) {
  const int c = (m + 1) / 2;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k) t.emplace_back((i * m + j) * m + k, ((i / 2) * c + j / 2) * c + k / 2, 1.0);
  Sparse p(m * m * m, c * c * c);
  p.setFromTriplets(t.begin(), t.end());
  return p;
}

// Levels down to at most 'coarsest' rows (or one level when coarsest >= m^3).
AmgCycle lattice_cycle(int m, MultigridSmoother smoother, int coarsest = 500) {
  std::vector<CsrRows> a, p;
  Sparse level = lattice_operator(m, 3);
  a.push_back(rows_of(level));
  while (level.rows() > coarsest) {
    const Sparse interpolation = aggregation(m);
    const Sparse coarse = Sparse(interpolation.transpose()) * level * interpolation;
    p.push_back(rows_of(interpolation));
    a.push_back(rows_of(coarse));
    level = coarse;
    m = (m + 1) / 2;
  }
  return AmgCycle(std::move(a), std::move(p), smoother);
}

std::vector<double> random_vector(int n, unsigned seed) {
  std::mt19937 gen(seed);
  std::normal_distribution<double> g;
  std::vector<double> v(n);
  for (double& x : v) x = g(gen);
  return v;
}

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

std::vector<double> applied(const AmgCycle& cycle, const std::vector<double>& r, bool team) {
  std::vector<double> z(r.size());
  cycle.apply(r.data(), z.data(), team);
  return z;
}

constexpr MultigridSmoother kSmoothers[] = {MultigridSmoother::kGaussSeidel, MultigridSmoother::kSplitGaussSeidel,
                                            MultigridSmoother::kJacobi};

}  // namespace

// u . M v = v . M u and u . M u > 0: a post-smoother that is not the pre-smoother's adjoint (the
// split smoother sweeping forwards both ways, say) breaks the first by far more than round-off.
TEST(AmgCycle, IsSymmetricAndPositiveForEverySmoother) {
  for (MultigridSmoother smoother : kSmoothers) {
    const AmgCycle cycle = lattice_cycle(40, smoother);  // 64 000 rows: several blocks on two levels
    ASSERT_GE(cycle.levels(), 3);
    const std::vector<double> u = random_vector(cycle.size(), 1), v = random_vector(cycle.size(), 2);
    const std::vector<double> mu = applied(cycle, u, false), mv = applied(cycle, v, false);
    const double scale = std::sqrt(dot(u, u) * dot(mv, mv));
    EXPECT_LE(std::abs(dot(u, mv) - dot(v, mu)), 1e-12 * scale) << static_cast<int>(smoother);
    EXPECT_GT(dot(u, mu), 0) << static_cast<int>(smoother);
  }
}

// The blocks are the level's, not the threads': a team gives the bits of one thread.
TEST(AmgCycle, GivesTheSameBitsOnATeamOfTwo) {
#ifndef _OPENMP
  GTEST_SKIP() << "built without OpenMP";
#else
  const int before = omp_get_max_threads();
  omp_set_num_threads(2);
  for (MultigridSmoother smoother : kSmoothers) {
    const AmgCycle cycle = lattice_cycle(40, smoother);
    ASSERT_GT(cycle.size(), kMinParallelLoop);
    const std::vector<double> r = random_vector(cycle.size(), 4);
    EXPECT_EQ(applied(cycle, r, false), applied(cycle, r, true)) << static_cast<int>(smoother);
    std::vector<double> one(r.size(), 1.0), two(r.size(), 1.0);
    cycle.multiply(-1.0, r.data(), 0.5, one.data(), false);
    cycle.multiply(-1.0, r.data(), 0.5, two.data(), true);
    EXPECT_EQ(one, two);
    EXPECT_EQ(fixed_chunk_dot(r.data(), one.data(), cycle.size(), false),
              fixed_chunk_dot(r.data(), one.data(), cycle.size(), true));
  }
  omp_set_num_threads(before);
#endif
}

// One level small enough to factorise: the cycle is A^-1.
TEST(AmgCycle, OneSmallLevelIsTheInverse) {
  const AmgCycle cycle = lattice_cycle(10, MultigridSmoother::kGaussSeidel, 1000);
  ASSERT_EQ(cycle.levels(), 1);
  const std::vector<double> b = random_vector(cycle.size(), 5);
  const std::vector<double> x = applied(cycle, b, false);
  std::vector<double> ax(b.size());
  cycle.multiply(1.0, x.data(), 0.0, ax.data(), false);
  for (std::size_t i = 0; i < b.size(); ++i) EXPECT_NEAR(ax[i], b[i], 1e-9 * std::sqrt(dot(b, b))) << i;
}

// A coarsest level too large to factorise is smoothed instead: the stationary iteration
// x += M (b - A x) then reduces the error in the energy norm at every step (a symmetric
// Gauss-Seidel sweep contracts it).
TEST(AmgCycle, ACoarsestLevelBeyondTheDenseBoundIsSmoothed) {
  const Sparse a = lattice_operator(24, 3);
  const AmgCycle cycle({rows_of(a)}, {}, MultigridSmoother::kGaussSeidel);  // one level, 13 824 rows
  ASSERT_GT(cycle.size(), AmgCycle::kMaxDenseRows);
  const std::vector<double> b = random_vector(cycle.size(), 6);
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct{Eigen::SparseMatrix<double>(a)};
  const Eigen::VectorXd exact = direct.solve(Eigen::Map<const Eigen::VectorXd>(b.data(), b.size()));
  const auto energy = [&](const std::vector<double>& x) {
    const Eigen::VectorXd e = Eigen::Map<const Eigen::VectorXd>(x.data(), x.size()) - exact;
    return std::sqrt(e.dot(a * e));
  };
  std::vector<double> x(b.size(), 0.0), r = b, ax(b.size());
  double last = energy(x);
  for (int k = 0; k < 5; ++k) {
    const std::vector<double> z = applied(cycle, r, false);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += z[i];
    cycle.multiply(1.0, x.data(), 0.0, ax.data(), false);
    for (std::size_t i = 0; i < r.size(); ++i) r[i] = b[i] - ax[i];
    const double now = energy(x);
    EXPECT_LT(now, last) << "iteration " << k;
    last = now;
  }
}

TEST(AmgCycle, RefusesLevelsThatDoNotChain) {
  const Sparse a = lattice_operator(8, 7), p = aggregation(8);
  const Sparse coarse = Sparse(p.transpose()) * a * p;
  // An interpolation to a level of another size.
  EXPECT_THROW(AmgCycle({rows_of(a), rows_of(coarse)}, {rows_of(aggregation(6))}, MultigridSmoother::kGaussSeidel),
               std::invalid_argument);
  // As many interpolations as levels.
  EXPECT_THROW(AmgCycle({rows_of(a)}, {rows_of(p)}, MultigridSmoother::kGaussSeidel), std::invalid_argument);
  // A column outside the matrix.
  CsrRows bad = rows_of(a);
  bad.column[3] = bad.n_cols;
  EXPECT_THROW(AmgCycle({bad}, {}, MultigridSmoother::kGaussSeidel), std::invalid_argument);
  // A row without a positive diagonal.
  Sparse negative = a;
  negative.coeffRef(5, 5) = -1;
  EXPECT_THROW(AmgCycle({rows_of(negative)}, {}, MultigridSmoother::kJacobi), std::invalid_argument);
}
