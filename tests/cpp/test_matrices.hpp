// Matrices for the solver tests, made without a mesh (no CGAL): symmetric positive definite
// and shaped like G, a graph Laplacian with conductances on the edges plus, on some unknowns, a
// coupling to a fixed outside value (a Dirichlet neighbour) that makes it definite.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv::test {

// G from its couplings (i, j, k > 0) and each unknown's coupling to the outside: off-diagonal
// -k, diagonal the sum of the unknown's couplings, as the pressure system assembles it.
inline std::shared_ptr<const SymmetricMatrix> from_couplings(int n, std::vector<std::tuple<int, int, double>> edges,
                                                             const std::vector<double>& outside) {
  std::vector<double> diagonal(outside);
  std::vector<std::vector<std::pair<int, double>>> column(n);  // (row < column, value)
  for (auto& [i, j, k] : edges) {
    if (i > j) std::swap(i, j);
    diagonal[i] += k;
    diagonal[j] += k;
    column[j].emplace_back(i, -k);
  }
  auto g = std::make_shared<SymmetricMatrix>();
  g->col_start.push_back(0);
  for (int j = 0; j < n; ++j) {
    std::sort(column[j].begin(), column[j].end());
    for (const auto& [i, v] : column[j]) {
      g->row.push_back(i);
      g->value.push_back(v);
    }
    g->row.push_back(j);
    g->value.push_back(diagonal[j]);
    g->col_start.push_back(static_cast<int>(g->row.size()));
  }
  return g;
}

// The 7-point Laplacian of an nx x ny x nz grid, unit conductances, the faces x = 0 and
// x = nx - 1 coupled to the outside (two pressure walls).
inline std::shared_ptr<const SymmetricMatrix> grid_laplacian(int nx, int ny, int nz) {
  const auto id = [&](int x, int y, int z) { return (z * ny + y) * nx + x; };
  const int n = nx * ny * nz;
  std::vector<std::tuple<int, int, double>> edges;
  std::vector<double> outside(n, 0.0);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        if (x + 1 < nx) edges.emplace_back(id(x, y, z), id(x + 1, y, z), 1.0);
        if (y + 1 < ny) edges.emplace_back(id(x, y, z), id(x, y + 1, z), 1.0);
        if (z + 1 < nz) edges.emplace_back(id(x, y, z), id(x, y, z + 1), 1.0);
        if (x == 0 || x == nx - 1) outside[id(x, y, z)] += 1.0;
      }
  return from_couplings(n, std::move(edges), outside);
}

// A random pattern of n unknowns: a chain (so that it is connected) plus random couplings within
// a band of 40 (a local pattern, whose factor fills as a mesh's does, not as a random graph's),
// at most four per unknown as in a tetrahedral mesh, conductances log-uniform over 'decades',
// and one unknown in twenty coupled to the outside.
inline std::shared_ptr<const SymmetricMatrix> random_spd(int n, unsigned seed, double decades = 2) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> exponent(0, decades);
  std::uniform_int_distribution<int> pick(0, n - 1), offset(2, 40);
  std::vector<int> degree(n, 0);
  std::vector<std::vector<int>> linked(n);
  std::vector<std::tuple<int, int, double>> edges;
  const auto link = [&](int a, int b) {
    if (a == b || degree[a] >= 4 || degree[b] >= 4) return;
    if (std::find(linked[a].begin(), linked[a].end(), b) != linked[a].end()) return;
    linked[a].push_back(b);
    linked[b].push_back(a);
    ++degree[a];
    ++degree[b];
    edges.emplace_back(a, b, std::pow(10.0, exponent(rng)));
  };
  for (int u = 0; u + 1 < n; ++u) link(u, u + 1);
  for (int t = 0; t < n; ++t) {
    const int a = pick(rng), b = a + offset(rng);
    if (b < n) link(a, b);
  }
  std::vector<double> outside(n, 0.0);
  for (int u = 0; u < n; u += 20) outside[u] = std::pow(10.0, exponent(rng));
  return from_couplings(n, std::move(edges), outside);
}

}  // namespace pfv::test
