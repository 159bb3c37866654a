#include "cholmod_solver.hpp"

#include <suitesparse/cholmod.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include <chrono>
#include <cstring>
#include <stdexcept>
#include <string>

#include "pressure_system.hpp"

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
  parallel_ = ParallelSubstitution{};  // it points into the factor just freed
}

double CholmodSolver::factor_nonzeros() const {
  return factor_ ? common_->c.lnz : 0.0;
}

double CholmodSolver::factor_flops() const {
  return factor_ ? common_->c.fl : 0.0;
}

void CholmodSolver::factorize(const PressureSystem& s, Ordering ordering) {
  release();
  cholmod_common* c = &common_->c;
  const int n = s.n_unknowns();
  if (n == 0) return;
  c->postorder = 1;
  if (ordering == Ordering::kAuto) {
    c->nmethods = 0;
  } else {
    c->nmethods = 1;
    c->method[0].ordering = ordering == Ordering::kAmd     ? CHOLMOD_AMD
                            : ordering == Ordering::kMetis ? CHOLMOD_METIS
                                                           : CHOLMOD_NESDIS;
  }
  // A view of the assembled arrays; CHOLMOD only reads them.
  cholmod_sparse a{};
  a.nrow = a.ncol = n;
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

  const auto t0 = std::chrono::steady_clock::now();
  cholmod_factor* f = cholmod_analyze(&a, c);
  analysis_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!f) throw std::runtime_error("CHOLMOD analysis failed (status " + std::to_string(c->status) + ")");
  factor_ = f;
  metis_used_ = c->method[c->selected].ordering == CHOLMOD_METIS || c->method[c->selected].ordering == CHOLMOD_NESDIS;
  cholmod_factorize(&a, f, c);
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
  rhs_ = cholmod_zeros(n, 1, CHOLMOD_REAL, c);
  if (f->is_super && f->is_ll) {
    SupernodalFactor view;
    view.n = n;
    view.nsuper = static_cast<int>(f->nsuper);
    view.super = static_cast<const int*>(f->super);
    view.pi = static_cast<const int*>(f->pi);
    view.px = static_cast<const int*>(f->px);
    view.rows = static_cast<const int*>(f->s);
    view.perm = static_cast<const int*>(f->Perm);
    view.values = static_cast<const double*>(f->x);
    parallel_.plan(view, 2);
  }
}

void CholmodSolver::solve(const std::vector<double>& rhs, std::vector<double>& x) {
#ifdef _OPENMP
  if (factor_ && parallel_.threads() > 1 && omp_get_max_threads() > 1) {
    x.resize(rhs.size());
    parallel_.solve(rhs.data(), x.data());
    return;
  }
#endif
  solve_serial(rhs, x);
}

void CholmodSolver::solve_serial(const std::vector<double>& rhs, std::vector<double>& x) {
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
