#include "pfv/linalg/ordering_reuse.hpp"

#include <algorithm>
#include <numeric>
#include <utility>

namespace pfv {

std::array<int, 4> CellOrdering::key_of(const std::array<int, 4>& vertices) {
  std::array<int, 4> k = vertices;
  std::sort(k.begin(), k.end());
  return k;
}

CellOrdering::CellOrdering(const CellGraph& cells, const int* perm, SupernodalChains tree, double fresh_fill,
                           OrderingOrigin origin)
    : n_spheres_(cells.n_spheres),
      n_(cells.n_unknowns()),
      tree_(std::move(tree)),
      fresh_fill_(fresh_fill),
      origin_(origin) {
  rank_.reserve(static_cast<std::size_t>(n_) * 2);
  for (int k = 0; k < n_; ++k) rank_.emplace(key_of(cells.vertices[cells.unknown_cell[perm[k]]]), k);
}

int CellOrdering::common_ancestor(int a, int b) const {
  if (tree_.chain_end.empty()) return b;  // no tree (simplicial factor): follow the latest
  // Subtrees are ranges ending at their root (postorder), so the ancestor of a that contains
  // b is the first one at or beyond b.
  while (a >= 0 && tree_.chain_end[a] < b) a = tree_.parent[tree_.chain_end[a]];  // up one supernode
  return a < 0 ? n_ : std::max(a, b);                                             // different roots: last
}

std::vector<int> CellOrdering::carry_over(const CellGraph& cells) const {
  if (cells.n_spheres != n_spheres_) return {};
  const int nc = cells.n_cells(), n = cells.n_unknowns();
  constexpr int kUnknown = -1;
  // Old position of each cell; a new cell gets the position it is eliminated after.
  std::vector<int> position(nc, kUnknown);
  std::vector<char> is_new(nc, 0);
  std::vector<int> fresh;
  for (int c = 0; c < nc; ++c) {
    const auto it = rank_.find(key_of(cells.vertices[c]));
    if (it != rank_.end()) {
      position[c] = it->second;
    } else {
      fresh.push_back(c);
      is_new[c] = 1;
    }
  }
  // Clusters of new cells resolve from their rim inwards, one layer per sweep; whatever stays
  // unresolved goes last.
  for (int sweep = 0; sweep < 8 && !fresh.empty(); ++sweep) {
    std::vector<std::pair<int, int>> resolved;
    std::vector<int> still;
    for (int c : fresh) {
      int lo = n_, hi = kUnknown;  // over the neighbours placed in the old tree
      for (int nb : cells.neighbours[c])
        if (nb >= 0 && position[nb] != kUnknown && position[nb] < n_) {
          lo = std::min(lo, position[nb]);
          hi = std::max(hi, position[nb]);
        }
      if (hi != kUnknown)
        resolved.emplace_back(c, common_ancestor(lo, hi));
      else
        still.push_back(c);
    }
    for (const auto& [c, p] : resolved) position[c] = p;  // after the sweep: one layer at a time
    fresh.swap(still);
    if (resolved.empty()) break;
  }
  for (int c : fresh) position[c] = n_;
  // Old cells keep their order; a new cell goes right after the position it was given.
  std::vector<long long> key(n);
  for (int u = 0; u < n; ++u) {
    const int c = cells.unknown_cell[u];
    key[u] = 2LL * position[c] + is_new[c];
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

}  // namespace pfv
