// Sparse Cholesky of G with CHOLMOD: analysed and factorised once per remesh, then only
// forward/back substitution each step, into buffers allocated at factorisation.
// Owns every CHOLMOD object it creates (YADE leaked factors here).
#pragma once
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "pfv/linalg/page_prefault.hpp"
#include "pfv/linalg/parallel_substitution.hpp"
#include "pfv/linalg/supernodal_numeric.hpp"
#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

// The elimination tree of a supernodal factor, in elimination positions: the columns of a
// supernode form a chain ending at chain_end; parent[chain_end] is the first column below the
// supernode's diagonal block (-1 at a root). Postordered, so every subtree is a contiguous
// range of positions ending at its root.
struct SupernodalChains {
  std::vector<int> chain_end, parent;
};

// Fill-reducing ordering. kCholmod: CHOLMOD's default rule (AMD, then METIS if AMD fills badly,
// the better kept); kGeometric: nested dissection by planes through the unknowns' positions
// (geometric_ordering.hpp); kAuto: CHOLMOD's rule below kGeometricFrom unknowns, kGeometric from
// there on.
enum class Ordering { kAuto, kAmd, kMetis, kNestedDissection, kCholmod, kGeometric };

// From this many unknowns kAuto orders by kGeometric. On sub-cubes of the benchmark packing
// (bench/solver_stages.py section 7) a nested dissection's factor has at most 0.7 x AMD's
// entries from 8 000 unknowns on and its solve is 1.15 x faster or more (2.4 x at 166 000), so
// its extra analysis is repaid within a few hundred steps, and later remeshes carry the order over; CHOLMOD's own
// rule keeps AMD up to about 20 000 unknowns and from there orders twice to keep METIS. The
// geometric dissection fills as little as METIS (0.96-1.01 x its entries) in 0.6-0.7 x its
// time. Below this size AMD's factor solves as fast and CHOLMOD's rule, with AMD's cheaper
// analysis, is kept.
inline constexpr int kGeometricFrom = 8000;

// Where an elimination order came from: minimum degree (AMD), METIS (or CHOLMOD's nested
// dissection, built on it) or the geometric dissection. A carried-over order keeps its origin.
enum class OrderingOrigin { kMinimumDegree, kMetis, kGeometric };

// kScaled32 keeps the factor, computed in double, as 32-bit integers with one double scale per
// column (in CHOLMOD's array): L(i, j) ~ q(i, j) * max_i |L(i, j)| / (2^31 - 1). Half the memory
// traffic of a substitution, whose result is then only an approximate inverse, to be used
// inside iterative refinement (refinement.hpp). The substitution still computes in double.
//
// Why not float: what limits an approximate factor inside refinement is its perturbation
// relative to each column, and the entries of a column of L are of similar size. Rounding
// them to float (24 bits relative to each entry) gives a contraction ||I - M^-1 G|| of
// about 20 times the contraction of 32-bit integers relative to the column's largest entry on
// the benchmark systems, for the same four bytes (doc/solvers.md).
// One pass from the previous step's pressures then meets the default
// tolerance; with float it needs two, and a second pass costs what the double solve saves.
enum class FactorPrecision { kDouble, kScaled32 };

// An elimination order of the unknowns to try before computing one (ordering_reuse.hpp): kept
// if its factor has at most max_fill entries per unknown.
struct GivenOrdering {
  std::vector<int> perm;  // perm[k] = unknown eliminated k-th; empty: none
  double max_fill = 0;
  OrderingOrigin origin = OrderingOrigin::kMinimumDegree;  // of the order it descends from
  // Ordering::kGeometric: computes the fresh order when none is given or the given one fills too much.
  std::function<std::vector<int>()> geometric;
};

// Which bound a factor exceeded: the caller's (set_max_entries), or the values CHOLMOD's 32-bit
// indices can address (CholmodSolver::kMaxIndexedValues), which no amount of memory lifts.
enum class FactorLimit { kBudget, kIndexRange };

// Thrown by CholmodSolver::factorize when the analysed factor would store more values than
// allowed: the solver is then as after release(), and no value was touched.
struct FactorTooLarge : std::runtime_error {
  FactorTooLarge(double stored, double bound, FactorLimit reason);
  double entries;  // values the supernodal factor would store (at least this many for kIndexRange)
  double limit;
  FactorLimit why;
};

class CholmodSolver {
 public:
  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  // Throws std::domain_error if G is not positive definite. A kScaled32 request falls back to
  // double when a column's scale is not a normal double (never for the pore networks; kept
  // because the format's error bound assumes it).
  // 'ordering' is computed unless 'given' is accepted.
  // kScaled32 applies to factors of at least min_scaled_entries stored entries (after compaction).
  void factorize(const SymmetricMatrix& g, Ordering ordering, FactorPrecision precision = FactorPrecision::kDouble,
                 const GivenOrdering& given = {}, double min_scaled_entries = 0);
  // Refactorises in double on the same ordering (no new analysis): for when refinement with
  // the 32-bit factor does not converge (G too ill-conditioned for it).
  void promote_to_double(const SymmetricMatrix& g);
  // x ~ G^-1 rhs; exact to round-off in double, an approximate inverse with kScaled32.
  // Always PFV's own substitution (parallel_substitution.hpp) on the compacted factor, whose
  // values CHOLMOD can no longer read: with two or more OpenMP threads on subtrees in parallel.
  void solve(const std::vector<double>& rhs, std::vector<double>& x);
  // See EngineSettings::cholmod_openmp_teams; applies to the factorisations that follow.
  void set_openmp_teams(bool on) { openmp_teams_ = on; }
  // A factorize() whose analysis projects more stored values than this throws FactorTooLarge
  // before the numeric factorisation (the analysis' cost is all that is spent).
  void set_max_entries(double entries) { max_entries_ = entries; }
  // CHOLMOD's int interface addresses at most 2^31 - 1 values (about 1 million spheres at the
  // benchmark packings' fill); its analysis of a larger factor fails with CHOLMOD_TOO_LARGE,
  // which factorize() reports as FactorTooLarge(kIndexRange), as it does any analysed factor
  // beyond index_range (this, unless lowered: a test hook, so that a small factor exceeds it).
  static constexpr double kMaxIndexedValues = 2147483647.0;
  void set_index_range_for_test(double entries) { index_range_ = entries; }
  // The same on the calling thread only (the same arithmetic, the same result).
  void solve_serial(const std::vector<double>& rhs, std::vector<double>& x);
  bool reduced_precision() const { return !scale_.empty(); }  // the kScaled32 format
  double parallel_top_fraction() const { return parallel_.top_fraction(); }
  int shared_top_supernodes() const { return parallel_.shared_top_supernodes(); }
  OrderingOrigin origin() const { return origin_; }
  bool metis_used() const { return origin_ == OrderingOrigin::kMetis; }
  bool ordering_given() const { return ordering_given_; }  // the given order was kept
  const int* permutation() const;                          // unknown eliminated k-th, after CHOLMOD's postorder
  double fill() const;                                     // factor entries per unknown
  SupernodalChains chains() const;
  bool ready() const { return factor_ != nullptr; }
  double factor_nonzeros() const;
  double factor_flops() const;
  double analysis_seconds() const { return analysis_seconds_; }  // ordering + symbolic
  // CHOLMOD's report of its last analysis and factorisation (cholmod_print_common, on stdout)
  // under 'title', then the ordering method selected and whether nested dissection ran.
  void print_statistics(const char* title) const;
  // Frees the factor but keeps the storage of its values for the next factorize(), which
  // reuses it when the new factor fits (see values_).
  void release();
  std::size_t value_capacity() const { return value_capacity_; }  // doubles, 0 before any factor
  struct FreeValues {  // the deleter of the values' storage (std::free: see lend_values)
    void operator()(double* p) const;
  };

 private:
  void solve_on(const std::vector<double>& rhs, std::vector<double>& x, bool threads);
  void numeric_factorization(const SymmetricMatrix& g);
  void lend_values(void* factor);  // cholmod_factor*, after the analysis
  // Compacts the factor, converts it to kScaled32 if it has at least min_scaled_entries entries
  // (kNever: stays double), and plans the substitution.
  void plan_substitution(const SymmetricMatrix& g, double min_scaled_entries);
  static constexpr double kNever = std::numeric_limits<double>::infinity();
  struct Common;
  Common* common_;
  bool openmp_teams_ = false;
  SupernodalWorkspace numeric_work_;
  double max_entries_ = kNever;
  double index_range_ = kMaxIndexedValues;
  void* factor_ = nullptr;  // cholmod_factor*
  // The factor's numeric values, lent to CHOLMOD (which otherwise allocates them afresh at
  // every factorisation). A factor of tens of thousands of spheres takes hundreds of MB; glibc
  // serves blocks that large from new mappings, whose first touch faults in every page. Kept
  // across release(), it makes the pages of one remesh the pages of the next. Only grown, with
  // 1/8 headroom for the next remeshes.
  std::unique_ptr<double[], FreeValues> values_;
  std::size_t value_capacity_ = 0;
  // Populates a fresh values_ block on another CPU while the first factorisation into it computes
  // (page_prefault.hpp); stopped when that factorisation ends and before the block is freed.
  PagePrefault prefault_;
  std::vector<long> trapezoid_start_;  // where each supernode's block starts (compacted values)
  std::vector<double> scale_;          // per column (elimination order) with kScaled32; empty in double
  ParallelSubstitution parallel_;
  OrderingOrigin origin_ = OrderingOrigin::kMinimumDegree;
  bool ordering_given_ = false;
  double analysis_seconds_ = 0;
};

}  // namespace pfv
