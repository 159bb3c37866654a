// Reuse of the fill-reducing ordering across remeshes.
//
// A remesh moves the spheres a little: most pore cells come back with the same four vertices,
// and the elimination order that METIS found for the old mesh is a good nested dissection of
// the new one. Finding it afresh is the largest single cost of a remesh (CHOLMOD's analysis),
// while carrying it over costs a hash lookup per cell. Cells that survive keep their old position. A new cell (from a
// flip) is eliminated right after the lowest common ancestor, in the old elimination tree, of its surviving neighbours,
// as if it had been in the separator that splits them: a few per cent more fill than a fresh METIS ordering for a small
// fraction of the analysis time (bench/solver_stages.py --sections=1; doc/solvers.md). Following the latest neighbour
// instead couples subtrees when a flip straddles a separator, and placing a new cell as low as the tree allows fills
// more. The caller checks the fill of the result against the fill of the last fresh ordering and orders afresh when it
// has drifted (cholmod_solver.hpp: GivenOrdering::max_fill).
#pragma once
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "pfv/linalg/cell_graph.hpp"
#include "pfv/linalg/cholmod_solver.hpp"

namespace pfv {

class CellOrdering {
 public:
  // From a factorisation of G over the unknowns of 'cells': its elimination order perm
  // (perm[k] = unknown eliminated k-th) and tree; fresh_fill = factor entries per unknown of the
  // last ordering computed from scratch (this one, or the one it descends from).
  CellOrdering(const CellGraph& cells, const int* perm, SupernodalChains tree, double fresh_fill,
               OrderingOrigin origin);

  // The elimination order carried over to a new mesh of the same spheres, or empty if the
  // spheres changed (then nothing can be matched).
  std::vector<int> carry_over(const CellGraph& cells) const;
  double fresh_fill() const { return fresh_fill_; }
  OrderingOrigin origin() const { return origin_; }

 private:
  struct KeyHash {
    std::size_t operator()(const std::array<int, 4>& k) const {
      std::uint64_t h = 1469598103934665603ull;
      for (int v : k) h = (h ^ static_cast<std::uint32_t>(v)) * 1099511628211ull;
      return static_cast<std::size_t>(h);
    }
  };
  static std::array<int, 4> key_of(const std::array<int, 4>& vertices);

  // The lowest common ancestor of positions a <= b in the old tree (n_ if none).
  int common_ancestor(int a, int b) const;

  int n_spheres_ = -1, n_ = 0;
  SupernodalChains tree_;
  double fresh_fill_ = 0;
  OrderingOrigin origin_ = OrderingOrigin::kMinimumDegree;
  std::unordered_map<std::array<int, 4>, int, KeyHash> rank_;  // cell (vertex set) -> position
};

}  // namespace pfv
