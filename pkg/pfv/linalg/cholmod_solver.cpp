#include "pfv/linalg/cholmod_solver.hpp"

#include <suitesparse/cholmod.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>

#include "pfv/common/parallel.hpp"
#include "pfv/linalg/serial_openmp.hpp"

namespace pfv {

struct CholmodSolver::Common {
  cholmod_common c;
};

CholmodSolver::CholmodSolver() : common_(new Common) {
  cholmod_start(&common_->c);
  common_->c.supernodal = CHOLMOD_SUPERNODAL;
  common_->c.print = 0;
}

CholmodSolver::~CholmodSolver() {
  release();
  cholmod_finish(&common_->c);
  delete common_;
}

void CholmodSolver::release() {
  prefault_.stop();
  cholmod_common* c = &common_->c;
  if (factor_) {
    auto* f = static_cast<cholmod_factor*>(factor_);
    if (f->x == values_.get()) {  // ours: CHOLMOD must not free it (it frees nothing at null)
      f->x = nullptr;
      f->xtype = CHOLMOD_PATTERN;
    }
    cholmod_free_factor(&f, c);
  }
  factor_ = nullptr;
  std::vector<double>().swap(scale_);
  parallel_ = ParallelSubstitution{};  // it points into the factor just freed
}

double CholmodSolver::factor_nonzeros() const { return factor_ ? common_->c.lnz : 0.0; }

const int* CholmodSolver::permutation() const {
  return factor_ ? static_cast<const int*>(static_cast<const cholmod_factor*>(factor_)->Perm) : nullptr;
}

SupernodalChains CholmodSolver::chains() const {
  SupernodalChains t;
  const auto* f = static_cast<const cholmod_factor*>(factor_);
  if (!f || !f->is_super) return t;
  const int n = static_cast<int>(f->n);
  t.chain_end.resize(n);
  t.parent.assign(n, -1);
  const auto* super = static_cast<const int*>(f->super);
  const auto* pi = static_cast<const int*>(f->pi);
  const auto* rows = static_cast<const int*>(f->s);
  for (std::size_t s = 0; s < f->nsuper; ++s) {
    const int k1 = super[s], k2 = super[s + 1], nscol = k2 - k1;
    for (int j = k1; j < k2; ++j) t.chain_end[j] = k2 - 1;
    if (pi[s + 1] - pi[s] > nscol) t.parent[k2 - 1] = rows[pi[s] + nscol];  // first row below the block
  }
  return t;
}

double CholmodSolver::fill() const {
  return factor_ ? common_->c.lnz / static_cast<double>(static_cast<const cholmod_factor*>(factor_)->n) : 0.0;
}

double CholmodSolver::factor_flops() const { return factor_ ? common_->c.fl : 0.0; }

void CholmodSolver::print_statistics(const char* title) const {
  cholmod_common* c = &common_->c;
  const int quiet = c->print;
  c->print = 3;
  cholmod_print_common(title, c);
  c->print = quiet;
  std::printf("cholmod method: %d\nMETIS called: %d\n", c->selected, c->called_nd);
  std::fflush(stdout);
}

namespace {

// A view of the assembled arrays; CHOLMOD only reads them.
cholmod_sparse view_of(const SymmetricMatrix& s) {
  cholmod_sparse a{};
  a.nrow = a.ncol = s.size();
  a.nzmax = s.value.size();
  a.p = const_cast<int*>(s.col_start.data());
  a.i = const_cast<int*>(s.row.data());
  a.x = const_cast<double*>(s.value.data());
  a.stype = 1;  // upper triangle stored
  a.itype = CHOLMOD_INT;
  a.xtype = CHOLMOD_REAL;
  a.dtype = CHOLMOD_DOUBLE;
  a.sorted = 1;
  a.packed = 1;
  return a;
}

}  // namespace

void CholmodSolver::factorize(const SymmetricMatrix& s, Ordering ordering, FactorPrecision precision,
                              const GivenOrdering& given, double min_scaled_entries) {
  release();
  cholmod_common* c = &common_->c;
  const int n = s.size();
  if (n == 0) return;
  c->postorder = 1;
  cholmod_sparse a = view_of(s);
  const auto t0 = std::chrono::steady_clock::now();
  cholmod_factor* f = nullptr;
  ordering_given_ = false;
  if (static_cast<int>(given.perm.size()) == n) {
    c->nmethods = 1;
    c->method[0].ordering = CHOLMOD_GIVEN;
    f = cholmod_analyze_p(&a, const_cast<int*>(given.perm.data()), nullptr, 0, c);
    ordering_given_ = f && c->lnz <= given.max_fill * n;
    if (f && !ordering_given_) cholmod_free_factor(&f, c);
    origin_ = given.origin;
  }
  const bool geometric = ordering == Ordering::kGeometric || (ordering == Ordering::kAuto && n >= kGeometricFrom);
  if (!ordering_given_ && geometric) {
    if (!given.geometric) throw std::invalid_argument("the geometric ordering needs the unknowns' positions");
    std::vector<int> perm = given.geometric();
    c->nmethods = 1;
    c->method[0].ordering = CHOLMOD_GIVEN;
    f = cholmod_analyze_p(&a, perm.data(), nullptr, 0, c);
    origin_ = OrderingOrigin::kGeometric;
  } else if (!ordering_given_) {
    if (ordering == Ordering::kCholmod || ordering == Ordering::kAuto) {
      c->nmethods = 0;
    } else {
      c->nmethods = 1;
      c->method[0].ordering = ordering == Ordering::kAmd     ? CHOLMOD_AMD
                              : ordering == Ordering::kMetis ? CHOLMOD_METIS
                                                             : CHOLMOD_NESDIS;
    }
    f = cholmod_analyze(&a, c);
    if (f) {
      const int selected = c->method[c->selected].ordering;
      origin_ = selected == CHOLMOD_METIS || selected == CHOLMOD_NESDIS ? OrderingOrigin::kMetis
                                                                        : OrderingOrigin::kMinimumDegree;
    }
  }
  analysis_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!f && c->status == CHOLMOD_TOO_LARGE)  // c->lnz: the column counts', fewer than the supernodes store
    throw FactorTooLarge(std::max(c->lnz, index_range_), index_range_, FactorLimit::kIndexRange);
  if (!f) throw std::runtime_error("CHOLMOD analysis failed (status " + std::to_string(c->status) + ")");
  const double stored = static_cast<double>(f->xsize);
  if (stored > index_range_ || stored > max_entries_) {
    cholmod_free_factor(&f, c);
    if (stored > index_range_) throw FactorTooLarge(stored, index_range_, FactorLimit::kIndexRange);
    throw FactorTooLarge(stored, max_entries_, FactorLimit::kBudget);
  }
  factor_ = f;
  try {  // out of memory on the way: no half-made factor may look ready
    lend_values(f);
    numeric_factorization(s);
    prefault_.stop();  // every page of the factor has been written
    plan_substitution(s, precision == FactorPrecision::kScaled32 ? min_scaled_entries : kNever);
  } catch (...) {
    release();
    throw;
  }
}

namespace {
std::string values_text(double values) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", values);
  return text;
}
}  // namespace

FactorTooLarge::FactorTooLarge(double stored, double bound, FactorLimit reason)
    : std::runtime_error("the Cholesky factor would store " + values_text(stored) + " values, more than " +
                         values_text(bound) +
                         (reason == FactorLimit::kIndexRange ? " (what CHOLMOD's 32-bit indices address)" : "")),
      entries(stored),
      limit(bound),
      why(reason) {}

void CholmodSolver::FreeValues::operator()(double* p) const { std::free(p); }

namespace {

// Storage of at least 'doubles' values, uninitialised (no page touched here). On 4 kB pages:
// the block is written first by a factorisation, whose page faults a helper takes on another
// CPU (lend_values). With Debian's default transparent-huge-page settings ("madvise" for both
// the mode and the defragmentation) a fault in a block advised for huge pages may reclaim and
// compact memory directly, and its first write measured several times slower than on 4 kB
// pages (doc/benchmarks.md, "Start-up"). Returns the capacity in doubles.
std::size_t allocate_values(std::size_t doubles, std::unique_ptr<double[], CholmodSolver::FreeValues>& out) {
  void* p = std::malloc(doubles * sizeof(double));
  if (!p) throw std::bad_alloc();
  out.reset(static_cast<double*>(p));
  return doubles;
}

// Blocks from this size on are populated by a helper while the first factorisation into them
// runs: below it, starting a thread costs about what it would save.
constexpr std::size_t kPrefaultFrom = std::size_t{8} << 20;

}  // namespace

void CholmodSolver::lend_values(void* factor) {
  // What cholmod_change_factor does to a symbolic supernodal factor before the numeric
  // factorisation, with our storage instead of a new block: the values are undefined until
  // the factorisation, which clears each supernode before assembling it.
  auto* f = static_cast<cholmod_factor*>(factor);
  if (!f->is_super || f->xtype != CHOLMOD_PATTERN) return;  // CHOLMOD allocates, as without us
  if (value_capacity_ < f->xsize) {
    values_.reset();  // the old storage first (release() has stopped any helper populating it)
    value_capacity_ = 0;
    value_capacity_ = allocate_values(f->xsize + f->xsize / 8, values_);
    // The factorisation's arithmetic outlasts the kernel's clearing of the pages it will write.
    if (f->xsize * sizeof(double) >= kPrefaultFrom) prefault_.start(values_.get(), f->xsize * sizeof(double));
  }
  f->x = values_.get();
  f->xtype = CHOLMOD_REAL;
  f->dtype = CHOLMOD_DOUBLE;
  f->minor = f->n;
}

void CholmodSolver::numeric_factorization(const SymmetricMatrix& s) {
  cholmod_common* c = &common_->c;
  auto* f = static_cast<cholmod_factor*>(factor_);
  const int n = s.size();
  std::size_t minor = static_cast<std::size_t>(n);
  if (openmp_teams_ || !f->is_super || !f->x) {
    cholmod_sparse a = view_of(s);
    if (openmp_teams_) {
      cholmod_factorize(&a, f, c);
    } else {
      const SerialOpenMpRegions serial;
      cholmod_factorize(&a, f, c);
    }
    minor = c->status == CHOLMOD_NOT_POSDEF ? std::min<std::size_t>(f->minor, n - 1) : f->minor;
  } else {
    // PFV's numeric phase on CHOLMOD's symbolic factor (supernodal_numeric.hpp: why).
    SupernodalSymbolic symbolic;
    symbolic.n = n;
    symbolic.nsuper = static_cast<int>(f->nsuper);
    symbolic.super = static_cast<const int*>(f->super);
    symbolic.pi = static_cast<const int*>(f->pi);
    symbolic.px = static_cast<const int*>(f->px);
    symbolic.rows = static_cast<const int*>(f->s);
    symbolic.perm = static_cast<const int*>(f->Perm);
    symbolic.max_update = static_cast<long>(f->maxcsize);
    const int failed = supernodal_numeric(symbolic, s, static_cast<double*>(f->x), numeric_work_);
    if (failed >= 0) minor = static_cast<std::size_t>(failed);
    f->is_ll = 1;
    f->minor = minor;
  }
  if (minor < static_cast<std::size_t>(n)) {
    release();
    throw std::domain_error(
        "singular pressure system: the conductance matrix is not positive definite "
        "(pivot " +
        std::to_string(minor) + " of " + std::to_string(n) + ")");
  }
  if (c->status < CHOLMOD_OK) {
    release();
    throw std::runtime_error("CHOLMOD factorisation failed (status " + std::to_string(c->status) + ")");
  }
}

void CholmodSolver::promote_to_double(const SymmetricMatrix& s) {
  if (!factor_ || !reduced_precision()) return;
  std::vector<double>().swap(scale_);
  numeric_factorization(s);  // on the symbolic factor kept from the analysis; overwrites the 32-bit values
  plan_substitution(s, kNever);
}

namespace {

// CHOLMOD stores supernode s as a full nsrow x nscol column-major block whose strict upper
// triangle is never used. The substitutions stream every stored byte, and on a pore network
// most supernodes are narrow (at 10 000 spheres the unused triangles are 18 % of the entries,
// and cache lines hold parts of them even when a kernel skips them), so each block is moved,
// in place, to its lower trapezoid: column j keeps rows j..nsrow-1. Returns where each block
// now starts. A block never moves to a higher address, so copying in increasing order only
// overwrites entries already moved.
std::vector<long> compact_to_trapezoids(double* v, const cholmod_factor& f) {
  const auto* super = static_cast<const int*>(f.super);
  const auto* pi = static_cast<const int*>(f.pi);
  const auto* px = static_cast<const int*>(f.px);
  std::vector<long> start(f.nsuper + 1);
  long out = 0;
  for (std::size_t s = 0; s < f.nsuper; ++s) {
    start[s] = out;
    const long nscol = super[s + 1] - super[s], nsrow = pi[s + 1] - pi[s];
    for (long j = 0; j < nscol; ++j) {
      const double* from = v + px[s] + j * nsrow + j;
      if (v + out != from) std::memmove(v + out, from, (nsrow - j) * sizeof(double));
      out += nsrow - j;
    }
  }
  start[f.nsuper] = out;
  return start;
}

// The compacted double values to 32-bit integers scaled per column, in place: integer k
// overwrites bytes of double k/2, which has been read already (a column is read whole, for
// its largest entry, before any of its integers is written). No allocation and no fresh pages
// to fault in (those cost more than the conversion). The bytes go through memcpy, which is how
// C++ lets one type's storage hold another's. False, with the values destroyed, if a scale is
// not a normal double.
bool scale_to_int32(double* v, const cholmod_factor& f, const std::vector<long>& start, std::vector<double>& scale) {
  const auto* super = static_cast<const int*>(f.super);
  const auto* pi = static_cast<const int*>(f.pi);
  auto* bytes = reinterpret_cast<unsigned char*>(v);
  constexpr double kMax = 2147483647.0;  // 2^31 - 1
  scale.resize(f.n);
  bool normal = true;
  for (std::size_t s = 0; s < f.nsuper; ++s) {
    const long nscol = super[s + 1] - super[s], nsrow = pi[s + 1] - pi[s];
    long at = start[s];
    for (long j = 0; j < nscol; ++j) {
      const long len = nsrow - j;
      double largest = 0;
      for (long i = 0; i < len; ++i) largest = std::max(largest, std::abs(v[at + i]));
      const double unit = largest / kMax;
      normal &= std::isnormal(unit);
      scale[super[s] + j] = unit;
      for (long i = 0; i < len; ++i) {
        const double q = std::clamp(std::nearbyint(v[at + i] / unit), -kMax, kMax);
        const auto k = static_cast<std::int32_t>(normal ? q : 0.0);
        std::memcpy(bytes + 4 * (at + i), &k, sizeof k);
      }
      at += len;
    }
  }
  return normal;
}

}  // namespace

void CholmodSolver::plan_substitution(const SymmetricMatrix& g, double min_scaled_entries) {
  auto* f = static_cast<cholmod_factor*>(factor_);
  if (!f->is_super || !f->is_ll) {  // CHOLMOD_SUPERNODAL is requested in the constructor
    release();
    throw std::logic_error("CHOLMOD returned a simplicial factor; ParallelSubstitution needs a supernodal LL'");
  }
  SupernodalFactor view;
  view.n = static_cast<int>(f->n);
  view.nsuper = static_cast<int>(f->nsuper);
  view.super = static_cast<const int*>(f->super);
  view.pi = static_cast<const int*>(f->pi);
  view.rows = static_cast<const int*>(f->s);
  view.perm = static_cast<const int*>(f->Perm);
  // From here on CHOLMOD's routines must not read the values (solve_serial never calls them).
  auto* v = static_cast<double*>(f->x);
  trapezoid_start_ = compact_to_trapezoids(v, *f);
  // Small factors stay double: they are served from the caches, where 32 bits gain nothing.
  if (trapezoid_start_.back() >= min_scaled_entries && !scale_to_int32(v, *f, trapezoid_start_, scale_)) {
    std::vector<double>().swap(scale_);  // stay double: factorise again, the values were overwritten
    numeric_factorization(g);
    v = static_cast<double*>(f->x);
    trapezoid_start_ = compact_to_trapezoids(v, *f);
  }
  if (reduced_precision()) {
    view.scaled = reinterpret_cast<const std::int32_t*>(v);
    view.scale = scale_.data();
  } else {
    view.values = v;
  }
  view.start = trapezoid_start_.data();
  parallel_.plan(view, 2);
}

void CholmodSolver::solve(const std::vector<double>& rhs, std::vector<double>& x) {
  solve_on(rhs, x, max_threads() > 1);
}

void CholmodSolver::solve_serial(const std::vector<double>& rhs, std::vector<double>& x) { solve_on(rhs, x, false); }

void CholmodSolver::solve_on(const std::vector<double>& rhs, std::vector<double>& x, bool threads) {
  if (!factor_) {
    x.clear();
    return;
  }
  x.resize(rhs.size());
  parallel_.solve(rhs.data(), x.data(), threads);
}

}  // namespace pfv
