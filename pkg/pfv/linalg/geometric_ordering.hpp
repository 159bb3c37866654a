// A fill-reducing elimination order from the positions of the unknowns: nested dissection by
// coordinate planes, the leaves and separators then ordered by constrained minimum degree (CAMD).
//
// The pore cells of a packing fill space evenly, so a plane through the median of the cells'
// points along the longest side of their box cuts the cell graph into halves joined by a layer
// of cells one cell thick, about as small as the separators METIS finds by coarsening and
// refining the graph, for a fraction of the work: the partition is a selection (nth_element)
// and one pass over the cut's edges per level. The separator is a minimum vertex cover of the
// edges the plane cuts (König's theorem on the bipartite cut), so no cell is taken that is
// not needed to disconnect the halves. CAMD then orders each level's cells by minimum degree,
// all leaves before the deepest separators and each separator before the ones above it, the
// order nested dissection prescribes.
#pragma once
#include <array>
#include <vector>

namespace pfv {

struct PressureSystem;

struct GeometricOrderingOptions {
  int leaf_size = 64;  // parts of at most this many unknowns (at least 2) are not split further
  // Half the band searched for the separator, in layers of m^(2/3) unknowns of a part of m.
  double band_layers = 2;
};

// perm[k] = unknown eliminated k-th, for system's G; point[u] is a point of unknown u's cell.
// Throws std::invalid_argument if point has not one entry per unknown.
std::vector<int> geometric_ordering(const PressureSystem& system, const std::vector<std::array<double, 3>>& point,
                                    const GeometricOrderingOptions& options = {});

}  // namespace pfv
