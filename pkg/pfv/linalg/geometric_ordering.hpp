// A fill-reducing elimination order from the positions of the unknowns: nested dissection by
// coordinate planes, the leaves and separators then ordered by constrained minimum degree (CAMD).
//
// The pore cells of a packing fill space evenly, so a plane through the median of a part's
// points, along the axis where it cuts the fewest edges, halves the part's cell graph across
// its smallest cross-section. The cells the plane cuts through make a rough separator, about a
// quarter larger than METIS's; the separator taken is instead the smallest set of cells, within
// a band of about two layers on either side of the plane, that disconnects the cells below the
// band from those above it: a minimum vertex cut, by maximum flow in the band graph (Menger).
// It follows the plane where nothing better is near and leaves it where it can, which makes it
// as small as the separators METIS finds by coarsening and refining the whole graph, for less
// work: one selection (nth_element) per level and a flow in a band of O(m^(2/3)) cells per part
// of m. CAMD then orders each level's cells by minimum degree, all leaves before the deepest
// separators and each separator before the ones above it, the order nested dissection
// prescribes (George 1973; the measurements in doc/solvers.md). Below the first few splits the
// parts are split in parallel by the OpenMP threads, each subtree by one thread; the order does
// not depend on the number of threads.
#pragma once
#include <array>
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

struct GeometricOrderingOptions {
  int leaf_size = 64;  // parts of at most this many unknowns (at least 2) are not split further
  // Half the band searched for the separator, in layers of m^(2/3) unknowns of a part of m.
  double band_layers = 2;
};

// perm[k] = unknown eliminated k-th, for G; point[u] is a point of unknown u's cell.
// Throws std::invalid_argument if point has not one entry per unknown.
std::vector<int> geometric_ordering(const SymmetricMatrix& g, const std::vector<std::array<double, 3>>& point,
                                    const GeometricOrderingOptions& options = {});

}  // namespace pfv
