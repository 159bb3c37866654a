#include "pfv/model/periodic_pressure_system.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace pfv {
namespace {

// d_f: from cell[f][0]'s power centre to that of the translate of cell[f][1].
Vec3 throat_vector(const CellGeometry& cells, const FacetGeometry& facets, int f) {
  return cells.power_centre[facets.cell[f][1]] + facets.translation[f] - cells.power_centre[facets.cell[f][0]];
}

void require_periodic(const FacetGeometry& facets, const std::vector<double>& k, const char* what) {
  if (static_cast<int>(facets.translation.size()) != facets.size())
    throw std::invalid_argument(std::string(what) + ": the facets are not those of a periodic mesh");
  if (static_cast<int>(k.size()) != facets.size())
    throw std::invalid_argument(std::string(what) + ": one conductance per facet is needed");
}

// The root of x's set, halving the path on the way.
int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<double> PeriodicPressureSystem::gather(const std::vector<double>& per_cell) const {
  std::vector<double> b(n_unknowns(), 0.0);
  for (std::size_t c = 0; c < unknown.size(); ++c)
    if (unknown[c] >= 0) b[unknown[c]] += per_cell[c];
  return b;
}

void PeriodicPressureSystem::add_known(const std::vector<double>& periodic_pressure, std::vector<double>& b) const {
  for (const Coupling& c : coupling) b[c.unknown] += c.k * periodic_pressure[c.cell];
}

std::vector<double> PeriodicPressureSystem::scatter(const std::vector<double>& x,
                                                    const std::vector<double>& known) const {
  std::vector<double> per_cell(unknown.size(), 0.0);
  for (std::size_t c = 0; c < unknown.size(); ++c) per_cell[c] = unknown[c] >= 0 ? x[unknown[c]] : known[c];
  return per_cell;
}

PeriodicPressureSystem assemble_periodic_system(const Mesh& mesh, const FacetGeometry& facets,
                                                const std::vector<double>& k, const std::vector<double>& storage,
                                                const std::vector<int>& imposed) {
  require_periodic(facets, k, "assemble_periodic_system");
  const int n = mesh.n_cells();
  if (n < 1) throw std::invalid_argument("assemble_periodic_system: no cells");
  if (!storage.empty() && static_cast<int>(storage.size()) != n)
    throw std::invalid_argument("assemble_periodic_system: one storage value per cell is needed");
  for (int c : imposed)
    if (c < 0 || c >= n) throw std::invalid_argument("assemble_periodic_system: an imposed cell is not a cell");
  PeriodicPressureSystem s;
  if (!storage.empty() || !imposed.empty()) s.reference_cell = -1;
  // Pores: the cells joined by zero-length throats.
  std::vector<int> parent(n);
  for (int c = 0; c < n; ++c) parent[c] = c;
  for (int f = 0; f < facets.size(); ++f)
    if (facets.length[f] == 0) parent[find_root(parent, facets.cell[f][0])] = find_root(parent, facets.cell[f][1]);
  s.unknown.assign(n, -1);
  std::vector<int> root_unknown(n, -1);
  std::vector<char> known_root(n, 0);
  if (s.reference_cell >= 0) known_root[find_root(parent, s.reference_cell)] = 1;
  for (int c : imposed) known_root[find_root(parent, c)] = 1;
  s.pore.assign(n, -1);
  std::vector<int> root_pore(n, -1);
  int pores = 0;
  for (int c = 0; c < n; ++c) {
    const int r = find_root(parent, c);
    if (root_pore[r] < 0) root_pore[r] = pores++;
    s.pore[c] = root_pore[r];
    if (known_root[r]) continue;
    if (root_unknown[r] < 0) {
      root_unknown[r] = static_cast<int>(s.unknown_cell.size());
      s.unknown_cell.push_back(c);
    }
    s.unknown[c] = root_unknown[r];
  }
  const int m = s.n_unknowns();  // 0 when the cell holds one pore (one sphere of a regular array)
  // Upper triangle by column: (row, column, value), rows <= columns, then merged.
  std::vector<std::pair<long long, double>> entries;
  entries.reserve(3 * static_cast<std::size_t>(facets.size()));
  std::vector<double> diagonal(m, 0.0);
  for (int f = 0; f < facets.size(); ++f) {
    const int a = facets.cell[f][0], b = facets.cell[f][1];
    const int ua = s.unknown[a], ub = s.unknown[b];
    if (ua == ub) continue;  // within one pore (or one pore and its translate), or two known: a source only
    if (ua >= 0) diagonal[ua] += k[f];
    if (ub >= 0) diagonal[ub] += k[f];
    if (ua >= 0 && ub >= 0)
      entries.emplace_back(static_cast<long long>(std::max(ua, ub)) * m + std::min(ua, ub), -k[f]);
    else if (ua >= 0)
      s.coupling.push_back({ua, b, k[f]});
    else if (ub >= 0)
      s.coupling.push_back({ub, a, k[f]});
  }
  if (!storage.empty())
    for (int c = 0; c < n; ++c) diagonal[s.unknown[c]] += storage[c];
  for (int u = 0; u < m; ++u) entries.emplace_back(static_cast<long long>(u) * m + u, diagonal[u]);
  std::sort(entries.begin(), entries.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
  auto g = std::make_shared<SymmetricMatrix>();
  g->col_start.assign(m + 1, 0);
  for (std::size_t e = 0; e < entries.size(); ++e) {
    if (e > 0 && entries[e].first == entries[e - 1].first) {
      g->value.back() += entries[e].second;  // two throats between one pair of cells
      continue;
    }
    const int column = static_cast<int>(entries[e].first / m);
    g->row.push_back(static_cast<int>(entries[e].first % m));
    g->value.push_back(entries[e].second);
    ++g->col_start[column + 1];
  }
  for (int c = 0; c < m; ++c) g->col_start[c + 1] += g->col_start[c];
  s.matrix = std::move(g);
  return s;
}

std::vector<double> gradient_source(const CellGeometry& cells, const FacetGeometry& facets,
                                    const std::vector<double>& k, const Vec3& gradient) {
  require_periodic(facets, k, "gradient_source");
  std::vector<double> s(cells.volume.size(), 0.0);
  for (int f = 0; f < facets.size(); ++f) {
    const double q = k[f] * gradient.dot(throat_vector(cells, facets, f));
    s[facets.cell[f][0]] += q;
    s[facets.cell[f][1]] -= q;
  }
  return s;
}

std::vector<double> periodic_fluxes(const CellGeometry& cells, const FacetGeometry& facets,
                                    const std::vector<double>& k, const std::vector<double>& periodic_pressure,
                                    const Vec3& gradient) {
  require_periodic(facets, k, "periodic_fluxes");
  std::vector<double> q(facets.size());
  for (int f = 0; f < facets.size(); ++f) {
    const int a = facets.cell[f][0], b = facets.cell[f][1];
    q[f] = k[f] * (periodic_pressure[a] - periodic_pressure[b] - gradient.dot(throat_vector(cells, facets, f)));
  }
  return q;
}

Vec3 mean_velocity(const CellGeometry& cells, const FacetGeometry& facets, const std::vector<double>& fluxes,
                   double volume) {
  Vec3 sum = Vec3::Zero();
  for (int f = 0; f < facets.size(); ++f) sum += fluxes[f] * throat_vector(cells, facets, f);
  return sum / volume;
}

}  // namespace pfv
