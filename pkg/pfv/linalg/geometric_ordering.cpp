#include "pfv/linalg/geometric_ordering.hpp"

#include <suitesparse/camd.h>

#include <boost/graph/boykov_kolmogorov_max_flow.hpp>
#include <boost/graph/compressed_sparse_row_graph.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <numeric>
#include <stdexcept>
#include <string>

#include "pfv/common/parallel.hpp"

namespace pfv {

namespace {

// G's pattern without the diagonal, both triangles, by rows.
struct Graph {
  std::vector<int> start, next;
};

Graph symmetric_pattern(const SymmetricMatrix& s) {
  const int n = s.size();
  Graph g;
  g.start.assign(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int e = s.col_start[j]; e < s.col_start[j + 1]; ++e)
      if (s.row[e] != j) {
        ++g.start[s.row[e] + 1];
        ++g.start[j + 1];
      }
  std::partial_sum(g.start.begin(), g.start.end(), g.start.begin());
  g.next.resize(g.start[n]);
  std::vector<int> fill(g.start.begin(), g.start.end() - 1);
  for (int j = 0; j < n; ++j)
    for (int e = s.col_start[j]; e < s.col_start[j + 1]; ++e)
      if (const int i = s.row[e]; i != j) {
        g.next[fill[i]++] = j;
        g.next[fill[j]++] = i;
      }
  return g;
}

// The maximum flow of a band graph and the source's side of its minimum cut. The flow is
// Boykov and Kolmogorov's algorithm (Boost.Graph): it grows search trees from both terminals
// and keeps them between augmentations, where a phase of Dinic's algorithm searches the whole
// band again; on these grid-like bands it needs a fraction of the time (doc/solvers.md). The cut
// is read by a breadth-first search of the residual graph from the source: the set it reaches
// is the same for every maximum flow (the minimum cut nearest the source), so the separator
// does not depend on how the flow was found. The storage is kept from one band to the next.
class MaxFlow {
 public:
  static constexpr int kInfinite = 1 << 30;

  void reset(int nodes) {
    nodes_ = nodes;
    added_.clear();
  }

  void add(int a, int b, int cap) { added_.push_back({a, b, cap}); }

  void run(int source, int sink) {
    arrange();
    using BandGraph = boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                                         boost::no_property, int, int>;
    using EdgeRef = BandGraph::edge_descriptor;
    const BandGraph g(boost::edges_are_sorted, arc_.begin(), arc_.end(), nodes_);
    reverse_arc_.resize(arc_.size());
    for (std::size_t e = 0; e < arc_.size(); ++e) reverse_arc_[e] = EdgeRef(arc_[e].second, reverse_[e]);
    predecessor_.resize(nodes_);
    colour_.resize(nodes_);
    distance_.resize(nodes_);
    const auto edge = boost::get(boost::edge_index, g);
    const auto vertex = boost::get(boost::vertex_index, g);
    boost::boykov_kolmogorov_max_flow(
        g, boost::make_iterator_property_map(cap_.begin(), edge), boost::make_iterator_property_map(res_.begin(), edge),
        boost::make_iterator_property_map(reverse_arc_.begin(), edge),
        boost::make_iterator_property_map(predecessor_.begin(), vertex),
        boost::make_iterator_property_map(colour_.begin(), vertex),
        boost::make_iterator_property_map(distance_.begin(), vertex), vertex, source, sink);
    reach(source);
  }

  // Whether the source reaches 'node' in the residual graph, after run(): the source's side of
  // a minimum cut.
  bool reached(int node) const { return reached_[node] != 0; }

 private:
  struct Edge {
    int from, to, cap;
  };

  // The added edges and their reverse arcs (capacity 0), grouped by the node they leave: the
  // arcs sorted by source, as the compressed graph takes them.
  void arrange() {
    start_.assign(nodes_ + 1, 0);
    for (const Edge& e : added_) {
      ++start_[e.from + 1];
      ++start_[e.to + 1];
    }
    std::partial_sum(start_.begin(), start_.end(), start_.begin());
    const std::size_t arcs = 2 * added_.size();
    arc_.resize(arcs);
    cap_.resize(arcs);
    res_.resize(arcs);
    reverse_.resize(arcs);
    fill_.assign(start_.begin(), start_.end() - 1);
    for (const Edge& e : added_) {
      const int forward = fill_[e.from]++, backward = fill_[e.to]++;
      arc_[forward] = {e.from, e.to};
      cap_[forward] = e.cap;
      reverse_[forward] = backward;
      arc_[backward] = {e.to, e.from};
      cap_[backward] = 0;
      reverse_[backward] = forward;
    }
  }

  void reach(int source) {
    reached_.assign(nodes_, 0);
    reached_[source] = 1;
    queue_.assign(1, source);
    for (std::size_t q = 0; q < queue_.size(); ++q) {
      const int a = queue_[q];
      for (int e = start_[a]; e < start_[a + 1]; ++e)
        if (res_[e] > 0 && !reached_[arc_[e].second]) {
          reached_[arc_[e].second] = 1;
          queue_.push_back(arc_[e].second);
        }
    }
  }

  int nodes_ = 0;
  std::vector<Edge> added_;
  std::vector<std::pair<int, int>> arc_;
  std::vector<int> start_, fill_, cap_, res_, reverse_, queue_;
  std::vector<char> reached_;
  std::vector<boost::compressed_sparse_row_graph<boost::directedS, boost::no_property, boost::no_property,
                                                 boost::no_property, int, int>::edge_descriptor>
      reverse_arc_, predecessor_;
  std::vector<boost::default_color_type> colour_;
  std::vector<int> distance_;
};

// The nested dissection. The per-unknown arrays are shared; a part's split reads and writes
// only the entries of the part's own unknowns, and reads those of its neighbours outside it,
// which lie in separators already taken out (part_ -1, never written again). So parts whose
// ranges of order_ are disjoint can be split concurrently, each by a Splitter with its own
// scratch, and the result is the same as splitting them one after the other.
class Dissection {
 public:
  Dissection(const Graph& g, const std::vector<std::array<double, 3>>& point, const GeometricOrderingOptions& o)
      : g_(g), point_(point), leaf_size_(std::max(o.leaf_size, 2)), band_layers_(o.band_layers) {
    const int n = static_cast<int>(point.size());
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), 0);
    part_.assign(n, 0);
    side_.assign(n, 0);
    slot_.assign(n, -1);
    median_sides_.assign(n, 0);
    level.assign(n, -1);
  }

  // Splits the unknowns down to the leaves; level[u] is then the depth of the separator
  // holding u, -1 for a leaf's unknown. The first splits run on the calling thread, breadth
  // first, until there are a few parts per OpenMP thread; the parts' subtrees are then split
  // in parallel, depth first.
  void run() {
    const int threads = max_threads();
    Splitter first(*this);
    std::vector<Part> parts{{0, static_cast<int>(order_.size()), 0}};
    if (threads == 1) {
      first.subtree(parts[0]);
      max_depth = first.max_depth;
      return;
    }
    const std::size_t enough = 2 * static_cast<std::size_t>(threads);
    std::size_t next = 0;  // parts before it are split or leaves
    for (; next < parts.size() && parts.size() - next < enough; ++next) first.split(parts[next], parts);
    const std::vector<Part> roots(parts.begin() + static_cast<std::ptrdiff_t>(next), parts.end());
    max_depth = first.max_depth;
    std::exception_ptr failure;
#pragma omp parallel
    {
      Splitter worker(*this);
#pragma omp for schedule(dynamic, 1) nowait
      for (std::size_t k = 0; k < roots.size(); ++k) try {
          worker.subtree(roots[k]);
        } catch (...) {
#pragma omp critical(pfv_geometric_ordering_failure)
          failure = std::current_exception();
        }
#pragma omp critical(pfv_geometric_ordering_depth)
      max_depth = std::max(max_depth, worker.max_depth);
    }
    if (failure) std::rethrow_exception(failure);
  }

  std::vector<int> level;
  int max_depth = -1;

 private:
  struct Part {
    int begin, end, depth;
  };

  // One thread's splitting of parts, with its scratch.
  class Splitter {
   public:
    explicit Splitter(Dissection& d)
        : d_(d),
          g_(d.g_),
          point_(d.point_),
          band_layers_(d.band_layers_),
          median_sides_(d.median_sides_),
          order_(d.order_),
          part_(d.part_),
          slot_(d.slot_),
          side_(d.side_) {}

    // Splits p and every part below it, depth first.
    void subtree(const Part& root) {
      std::vector<Part> todo{root};
      while (!todo.empty()) {
        const Part p = todo.back();
        todo.pop_back();
        split(p, todo);
      }
    }

    // Splits p unless it is a leaf, appending its two sides to 'out'.
    void split(const Part p, std::vector<Part>& out) {
      if (p.end - p.begin <= d_.leaf_size_) return;
      const int id = part_[order_[p.begin]];
      separate(p.begin, p.end, best_axis(p.begin, p.end), id);
      max_depth = std::max(max_depth, p.depth);
      // Lower side, upper side, then the separator (the unknowns taken out of the part).
      const auto sep =
          std::stable_partition(order_.begin() + p.begin, order_.begin() + p.end, [&](int u) { return part_[u] >= 0; });
      for (auto k = sep; k != order_.begin() + p.end; ++k) d_.level[*k] = p.depth;
      const auto upper = std::stable_partition(order_.begin() + p.begin, sep, [&](int u) { return side_[u] == 0; });
      const int r = static_cast<int>(upper - order_.begin()), s = static_cast<int>(sep - order_.begin());
      // Nothing separated (a small part whose lower core the band took in): a leaf.
      if (r - p.begin == p.end - p.begin || s - r == p.end - p.begin) return;
      const int lower_id = ++d_.parts_, upper_id = ++d_.parts_;
      for (int k = p.begin; k < r; ++k) part_[order_[k]] = lower_id;
      for (int k = r; k < s; ++k) part_[order_[k]] = upper_id;
      out.push_back({p.begin, r, p.depth + 1});
      out.push_back({r, s, p.depth + 1});
    }

    int max_depth = -1;

   private:
    // order_[begin, end) partitioned about its nth smallest coordinate along 'axis'. The selection
    // runs on (coordinate, unknown) pairs copied in order_'s order: the same comparisons as on
    // order_ itself, so the same permutation, without a scattered read of point_ per comparison.
    void select(int begin, int nth, int end, int axis) {
      keyed_.resize(end - begin);
      for (int k = begin; k < end; ++k) keyed_[k - begin] = {point_[order_[k]][axis], order_[k]};
      std::nth_element(keyed_.begin(), keyed_.begin() + (nth - begin), keyed_.end(),
                       [](const Keyed& a, const Keyed& b) { return a.key < b.key; });
      for (int k = begin; k < end; ++k) order_[k] = keyed_[k - begin].unknown;
    }

    // The axis whose median plane cuts the fewest edges of the part (the smallest cross-section).
    // The three medians come from one gathered copy of the part's points, and one pass over the
    // part's edges counts the crossings of all three planes, each unknown's sides packed in a byte
    // (bit a: below the median along axis a; bit 3: in this part). The unknowns below a median
    // are the same as the lower half of the selection separate() makes, unless coordinates tie.
    int best_axis(int begin, int end) {
      const int m = end - begin;
      gathered_.resize(m);
      for (int k = 0; k < m; ++k) gathered_[k] = point_[order_[begin + k]];
      double median[3];
      coordinate_.resize(m);
      for (int axis = 0; axis < 3; ++axis) {
        for (int k = 0; k < m; ++k) coordinate_[k] = gathered_[k][axis];
        std::nth_element(coordinate_.begin(), coordinate_.begin() + m / 2, coordinate_.end());
        median[axis] = coordinate_[m / 2];
      }
      constexpr unsigned char kInPart = 8;
      for (int k = 0; k < m; ++k) {
        const auto& x = gathered_[k];
        median_sides_[order_[begin + k]] = static_cast<unsigned char>(
            kInPart | (x[0] < median[0]) | (x[1] < median[1]) << 1 | (x[2] < median[2]) << 2);
      }
      long cut[3] = {0, 0, 0};
      for (int k = begin; k < end; ++k) {
        const int u = order_[k];
        const unsigned below = median_sides_[u] & 7u;
        if (below == 0) continue;
        for (int e = g_.start[u]; e < g_.start[u + 1]; ++e) {
          const unsigned v = median_sides_[g_.next[e]];
          const unsigned crossing = v & kInPart ? below & ~v & 7u : 0u;  // u below, v above the plane
          cut[0] += crossing & 1u;
          cut[1] += crossing >> 1 & 1u;
          cut[2] += crossing >> 2;
        }
      }
      for (int k = begin; k < end; ++k) median_sides_[order_[k]] = 0;
      int best = 0;
      for (int axis = 1; axis < 3; ++axis)
        if (cut[axis] < cut[best]) best = axis;
      return best;
    }

    // The smallest vertex separator, among the unknowns of a band around the median plane along
    // 'axis', between the unknowns below and above the band: a minimum cut of the band graph
    // with each band unknown split in two joined by a unit capacity (Menger's theorem). Marks the
    // separator part_ = -1 and every other unknown of the part with its side_ (0 below, 1 above).
    void separate(int begin, int end, int axis, int id) {
      const int m = end - begin, mid = begin + m / 2;
      // At most half the part in the band, so that both sides keep a core (m >= 4).
      const int half =
          std::max(1, std::min(static_cast<int>(band_layers_ * std::cbrt(static_cast<double>(m) * m)), m / 4));
      const int lo = mid - half, hi = mid + half;
      select(begin, mid, end, axis);
      select(begin, lo, mid, axis);
      select(mid, hi, end, axis);
      // side_ 0: below the band, 1: above, 2: in it; an edge from below to above pulls its lower end in.
      for (int k = begin; k < end; ++k) side_[order_[k]] = k < lo ? 0 : k < hi ? 2 : 1;
      band_.clear();
      for (int k = begin; k < end; ++k) {
        const int u = order_[k];
        if (side_[u] == 0)
          for (int e = g_.start[u]; e < g_.start[u + 1]; ++e)
            if (part_[g_.next[e]] == id && side_[g_.next[e]] == 1) {
              side_[u] = 2;
              break;
            }
        if (side_[u] == 2) {
          slot_[u] = static_cast<int>(band_.size());
          band_.push_back(u);
        }
      }
      // Nodes: 0 the source (below), 1 the sink (above), 2 + 2k and 3 + 2k the entry and exit of
      // band unknown k.
      const int nb = static_cast<int>(band_.size());
      flow_.reset(2 + 2 * nb);
      for (int k = 0; k < nb; ++k) {
        const int u = band_[k];
        flow_.add(2 + 2 * k, 3 + 2 * k, 1);
        bool below = false, above = false;
        for (int e = g_.start[u]; e < g_.start[u + 1]; ++e) {
          const int v = g_.next[e];
          if (part_[v] != id) continue;
          if (side_[v] == 2)
            flow_.add(3 + 2 * k, 2 + 2 * slot_[v], MaxFlow::kInfinite);
          else
            (side_[v] == 0 ? below : above) = true;
        }
        if (below) flow_.add(0, 2 + 2 * k, MaxFlow::kInfinite);
        if (above) flow_.add(3 + 2 * k, 1, MaxFlow::kInfinite);
      }
      flow_.run(0, 1);
      for (int k = 0; k < nb; ++k) {
        const bool in = flow_.reached(2 + 2 * k), out = flow_.reached(3 + 2 * k);
        if (in && !out)
          part_[band_[k]] = -1;  // a saturated unit edge of the cut
        else
          side_[band_[k]] = out ? 0 : 1;
      }
    }

    Dissection& d_;
    const Graph& g_;
    const std::vector<std::array<double, 3>>& point_;
    const double band_layers_;
    std::vector<unsigned char>& median_sides_;
    std::vector<int>&order_, &part_, &slot_;
    std::vector<char>& side_;
    MaxFlow flow_;
    struct Keyed {
      double key;
      int unknown;
    };
    std::vector<Keyed> keyed_;
    std::vector<std::array<double, 3>> gathered_;
    std::vector<double> coordinate_;
    std::vector<int> band_;
  };

  const Graph& g_;
  const std::vector<std::array<double, 3>>& point_;
  const int leaf_size_;
  const double band_layers_;
  std::vector<unsigned char> median_sides_;  // best_axis: the sides of a part's unknowns, 0 elsewhere
  std::vector<int> order_, part_, slot_;
  std::vector<char> side_;
  std::atomic<int> parts_{0};
};

}  // namespace

std::vector<int> geometric_ordering(const SymmetricMatrix& s, const std::vector<std::array<double, 3>>& point,
                                    const GeometricOrderingOptions& options) {
  const int n = s.size();
  if (static_cast<int>(point.size()) != n)
    throw std::invalid_argument("geometric ordering: " + std::to_string(point.size()) + " points for " +
                                std::to_string(n) + " unknowns");
  for (const auto& p : point)
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      throw std::invalid_argument("geometric ordering: a point is not finite");
  std::vector<int> perm(n);
  if (n == 0) return perm;
  const Graph g = symmetric_pattern(s);
  Dissection d(g, point, options);
  d.run();
  // CAMD eliminates constraint class 0 first: the leaves, then the separators from the deepest up.
  std::vector<int> constraint(n);
  for (int u = 0; u < n; ++u) constraint[u] = d.level[u] < 0 ? 0 : d.max_depth + 1 - d.level[u];
  double control[CAMD_CONTROL], info[CAMD_INFO];
  camd_defaults(control);
  const int status = camd_order(n, s.col_start.data(), s.row.data(), perm.data(), control, info, constraint.data());
  if (status < CAMD_OK) throw std::runtime_error("CAMD ordering failed (status " + std::to_string(status) + ")");
  return perm;
}

}  // namespace pfv
