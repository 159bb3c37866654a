#include "pfv/model/pressure_system.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace pfv {

PressureSystem assemble_pressure_system(const Mesh& mesh, const FacetGeometry& facets, const std::vector<double>& k,
                                        const BoundaryConditions& bc, const std::vector<int>& imposed_cells,
                                        const std::vector<double>& storage, const CellConditions& cells) {
  const int nc = mesh.n_cells();
  PressureSystem s;
  s.source.assign(nc, BoundarySource::unknown());
  for (int c = 0; c < nc; ++c)
    for (int v : mesh.cell_vertices[c]) {  // later walls win, as in YADE
      if (!mesh.is_wall(v) || !bc.is_pressure[mesh.wall_of(v)]) continue;
      const int w = mesh.wall_of(v);
      if (!s.source[c].is_wall() || w > s.source[c].index) s.source[c] = BoundarySource::wall(w);
    }
  for (std::size_t i = 0; i < imposed_cells.size(); ++i)
    if (imposed_cells[i] >= 0) s.source[imposed_cells[i]] = BoundarySource::imposed_point(static_cast<int>(i));
  if (!cells.pressure.empty())
    for (int c = 0; c < nc; ++c) {
      if (cells.pressure[c] == CellPressure::kImposed) s.source[c] = BoundarySource::cell_imposed();
      if (cells.pressure[c] == CellPressure::kFree) s.source[c] = BoundarySource::unknown();
    }
  if (!cells.blocked.empty())
    for (int c = 0; c < nc; ++c)
      if (cells.blocked[c]) s.source[c] = BoundarySource::blocked();

  s.unknown.assign(nc, -1);
  for (int c = 0; c < nc; ++c)
    if (s.source[c].is_unknown()) {
      s.unknown[c] = static_cast<int>(s.unknown_cell.size());
      s.unknown_cell.push_back(c);
    }

  // Adjacency (CSR) from the two-sided facets.
  s.adj_start.assign(nc + 1, 0);
  for (int f = 0; f < facets.size(); ++f)
    if (facets.cell[f][1] >= 0) {
      ++s.adj_start[facets.cell[f][0] + 1];
      ++s.adj_start[facets.cell[f][1] + 1];
    }
  std::partial_sum(s.adj_start.begin(), s.adj_start.end(), s.adj_start.begin());
  s.adj_cell.resize(s.adj_start[nc]);
  s.adj_k.resize(s.adj_start[nc]);
  std::vector<int> fill(s.adj_start.begin(), s.adj_start.end() - 1);
  s.diagonal.assign(nc, 0.0);
  for (int f = 0; f < facets.size(); ++f) {
    const int a = facets.cell[f][0], b = facets.cell[f][1];
    if (b < 0) continue;
    const double kf = s.source[a].is_blocked() || s.source[b].is_blocked() ? 0.0 : k[f];
    s.adj_cell[fill[a]] = b;
    s.adj_k[fill[a]++] = kf;
    s.adj_cell[fill[b]] = a;
    s.adj_k[fill[b]++] = kf;
    s.diagonal[a] += kf;
    s.diagonal[b] += kf;
  }

  if (!storage.empty())
    for (int c = 0; c < nc; ++c) s.diagonal[c] += storage[c];

  // Every connected group of unknowns must reach a Dirichlet cell (or a compressible cell),
  // else G is singular.
  std::vector<char> reached(nc, 0);
  std::vector<int> stack;
  for (int c = 0; c < nc; ++c)
    if (s.unknown[c] < 0 || (!storage.empty() && storage[c] > 0)) {
      reached[c] = 1;
      stack.push_back(c);
    }
  while (!stack.empty()) {
    const int c = stack.back();
    stack.pop_back();
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e)
      if (s.adj_k[e] > 0 && !reached[s.adj_cell[e]]) {
        reached[s.adj_cell[e]] = 1;
        stack.push_back(s.adj_cell[e]);
      }
  }
  const int isolated = static_cast<int>(std::count(reached.begin(), reached.end(), 0));
  if (isolated > 0) {
    const bool none =
        std::none_of(s.source.begin(), s.source.end(), [](const BoundarySource& x) { return x.imposes_pressure(); });
    throw std::domain_error(none ? "singular pressure system: no boundary has an imposed pressure (set "
                                   "bndCondIsPressure on at least one wall, or imposePressure somewhere)"
                                 : "singular pressure system: " + std::to_string(isolated) +
                                       " pore cells are not connected to any imposed pressure");
  }

  // Upper triangle by column over unknowns.
  const int nu = s.n_unknowns();
  auto g = std::make_shared<SymmetricMatrix>();
  g->col_start.assign(nu + 1, 0);
  for (int u = 0; u < nu; ++u) {
    const int c = s.unknown_cell[u];
    int count = 1;
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) {
      const int v = s.unknown[s.adj_cell[e]];
      if (v >= 0 && v < u) ++count;
    }
    g->col_start[u + 1] = g->col_start[u] + count;
  }
  g->row.resize(g->col_start[nu]);
  g->value.resize(g->col_start[nu]);
  std::vector<std::pair<int, double>> entries;
  for (int u = 0; u < nu; ++u) {
    const int c = s.unknown_cell[u];
    int pos = g->col_start[u];
    entries.clear();
    for (int e = s.adj_start[c]; e < s.adj_start[c + 1]; ++e) {
      const int v = s.unknown[s.adj_cell[e]];
      if (v >= 0 && v < u) entries.emplace_back(v, -s.adj_k[e]);
    }
    std::sort(entries.begin(), entries.end());
    for (const auto& [r, x] : entries) {
      g->row[pos] = r;
      g->value[pos++] = x;
    }
    g->row[pos] = u;
    g->value[pos] = s.diagonal[c];
  }
  s.matrix = std::move(g);
  return s;
}

void apply_dirichlet_values(const PressureSystem& s, const BoundaryConditions& bc, std::vector<double>& p) {
  for (std::size_t c = 0; c < s.source.size(); ++c) {
    const BoundarySource& src = s.source[c];
    if (src.is_wall())
      p[c] = bc.value[src.index];
    else if (src.is_imposed_point())
      p[c] = bc.imposed_pressure[src.index].value;
  }
}

}  // namespace pfv
