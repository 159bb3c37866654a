#include "cholmod_solver.hpp"

#include <suitesparse/cholmod.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "pressure_system.hpp"
#include "serial_openmp.hpp"

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
  cholmod_common* c = &common_->c;
  if (factor_) {
    auto* f = static_cast<cholmod_factor*>(factor_);
    cholmod_free_factor(&f, c);
  }
  for (void** d : {&rhs_, &x_, &work_y_, &work_e_})
    if (*d) {
      auto* m = static_cast<cholmod_dense*>(*d);
      cholmod_free_dense(&m, c);
      *d = nullptr;
    }
  factor_ = nullptr;
  values32_ = nullptr;
  parallel_ = ParallelSubstitution{};  // it points into the factor just freed
}

double CholmodSolver::factor_nonzeros() const {
  return factor_ ? common_->c.lnz : 0.0;
}

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

double CholmodSolver::factor_flops() const {
  return factor_ ? common_->c.fl : 0.0;
}

namespace {

// A view of the assembled arrays; CHOLMOD only reads them.
cholmod_sparse view_of(const PressureSystem& s) {
  cholmod_sparse a{};
  a.nrow = a.ncol = s.n_unknowns();
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

void CholmodSolver::factorize(const PressureSystem& s, Ordering ordering, FactorPrecision precision,
                             const GivenOrdering& given) {
  release();
  cholmod_common* c = &common_->c;
  const int n = s.n_unknowns();
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
    metis_used_ = given.from_metis;
  }
  if (!ordering_given_) {
    if (ordering == Ordering::kAuto) {
      c->nmethods = 0;
    } else {
      c->nmethods = 1;
      c->method[0].ordering = ordering == Ordering::kAmd     ? CHOLMOD_AMD
                              : ordering == Ordering::kMetis ? CHOLMOD_METIS
                                                             : CHOLMOD_NESDIS;
    }
    f = cholmod_analyze(&a, c);
  }
  analysis_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!f) throw std::runtime_error("CHOLMOD analysis failed (status " + std::to_string(c->status) + ")");
  factor_ = f;
  if (!ordering_given_)
    metis_used_ = c->method[c->selected].ordering == CHOLMOD_METIS || c->method[c->selected].ordering == CHOLMOD_NESDIS;
  numeric_factorization(s);
  rhs_ = cholmod_zeros(n, 1, CHOLMOD_REAL, c);

  if (precision == FactorPrecision::kSingle && f->is_super && f->is_ll) {
    // Round in place, into the first half of CHOLMOD's own array: float i overwrites bytes of
    // double i/2, which has been read already. No allocation and no fresh pages to fault in
    // (those cost more than the rounding: 30 ms for the 8e6 entries at 10 000 spheres). The
    // bytes are copied with memcpy, which is how C++ lets one type's storage hold another's.
    auto* bytes = static_cast<unsigned char*>(f->x);
    const std::size_t count = static_cast<const int*>(f->px)[f->nsuper];
    bool representable = true;
    for (std::size_t i = 0; i < count; ++i) {
      double d;
      std::memcpy(&d, bytes + 8 * i, sizeof d);
      const float v = static_cast<float>(d);
      // Overflow, NaN, or a non-zero that float cannot hold normally (subnormal or zero).
      representable &= std::isfinite(v) & ((d == 0) | (std::abs(v) >= FLT_MIN));
      std::memcpy(bytes + 4 * i, &v, sizeof v);
    }
    if (representable) {
      values32_ = reinterpret_cast<const float*>(bytes);
    } else {
      numeric_factorization(s);  // the doubles were overwritten: factorise again, stay double
    }
  }
  plan_substitution();
}

void CholmodSolver::numeric_factorization(const PressureSystem& s) {
  cholmod_common* c = &common_->c;
  auto* f = static_cast<cholmod_factor*>(factor_);
  const int n = s.n_unknowns();
  cholmod_sparse a = view_of(s);
  if (openmp_teams_) {
    cholmod_factorize(&a, f, c);
  } else {
    const SerialOpenMpRegions serial;
    cholmod_factorize(&a, f, c);
  }
  if (c->status == CHOLMOD_NOT_POSDEF || f->minor < static_cast<size_t>(n)) {
    const auto minor = f->minor;
    release();
    throw std::domain_error("singular pressure system: the conductance matrix is not positive definite "
                            "(pivot " + std::to_string(minor) + " of " + std::to_string(n) + ")");
  }
  if (c->status < CHOLMOD_OK) {
    release();
    throw std::runtime_error("CHOLMOD factorisation failed (status " + std::to_string(c->status) + ")");
  }
}

void CholmodSolver::promote_to_double(const PressureSystem& s) {
  if (!factor_ || !single_precision()) return;
  values32_ = nullptr;
  numeric_factorization(s);  // on the symbolic factor kept from the analysis; overwrites the rounded values
  plan_substitution();
}

void CholmodSolver::plan_substitution() {
  const auto* f = static_cast<const cholmod_factor*>(factor_);
  if (!f->is_super || !f->is_ll) return;
  SupernodalFactor view;
  view.n = static_cast<int>(f->n);
  view.nsuper = static_cast<int>(f->nsuper);
  view.super = static_cast<const int*>(f->super);
  view.pi = static_cast<const int*>(f->pi);
  view.px = static_cast<const int*>(f->px);
  view.rows = static_cast<const int*>(f->s);
  view.perm = static_cast<const int*>(f->Perm);
  if (single_precision())
    view.values32 = values32_;
  else
    view.values = static_cast<const double*>(f->x);
  parallel_.plan(view, 2);
}

void CholmodSolver::solve(const std::vector<double>& rhs, std::vector<double>& x) {
#ifdef _OPENMP
  const bool threads = omp_get_max_threads() > 1;
#else
  const bool threads = false;
#endif
  if (factor_ && (single_precision() || (threads && parallel_.threads() > 1))) {
    x.resize(rhs.size());
    parallel_.solve(rhs.data(), x.data(), threads);
    return;
  }
  solve_serial(rhs, x);
}

void CholmodSolver::solve_serial(const std::vector<double>& rhs, std::vector<double>& x) {
  if (single_precision()) {
    x.resize(rhs.size());
    parallel_.solve(rhs.data(), x.data(), false);
    return;
  }
  if (!factor_) {
    x.clear();
    return;
  }
  cholmod_common* c = &common_->c;
  auto* b = static_cast<cholmod_dense*>(rhs_);
  std::memcpy(b->x, rhs.data(), rhs.size() * sizeof(double));
  auto* xd = static_cast<cholmod_dense*>(x_);
  auto* y = static_cast<cholmod_dense*>(work_y_);
  auto* e = static_cast<cholmod_dense*>(work_e_);
  // cholmod_solve2 allocates x, y, e on the first call and reuses them afterwards.
  cholmod_solve2(CHOLMOD_A, static_cast<cholmod_factor*>(factor_), b, nullptr, &xd, nullptr, &y, &e, c);
  x_ = xd;
  work_y_ = y;
  work_e_ = e;
  x.assign(static_cast<double*>(xd->x), static_cast<double*>(xd->x) + rhs.size());
}

}  // namespace pfv
