#include "pfv/linalg/amg_pcg.hpp"

#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <_hypre_parcsr_ls.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "pfv/common/parallel.hpp"
#include "pfv/common/stage_timer.hpp"
#include "pfv/linalg/amg_cycle.hpp"
#include "pfv/linalg/solution_history.hpp"

namespace pfv {
namespace {

void check(HYPRE_Int status, const char* what) {
  if (status != 0) {
    HYPRE_ClearAllErrors();
    throw std::runtime_error(std::string("hypre: ") + what + " failed (error code " + std::to_string(status) + ")");
  }
}

struct MatrixDeleter {
  void operator()(HYPRE_IJMatrix m) const { HYPRE_IJMatrixDestroy(m); }
};
struct VectorDeleter {
  void operator()(HYPRE_IJVector v) const { HYPRE_IJVectorDestroy(v); }
};
struct SolverDeleter {
  void operator()(HYPRE_Solver s) const { HYPRE_BoomerAMGDestroy(s); }
};
using MatrixHandle = std::unique_ptr<std::remove_pointer_t<HYPRE_IJMatrix>, MatrixDeleter>;
using VectorHandle = std::unique_ptr<std::remove_pointer_t<HYPRE_IJVector>, VectorDeleter>;
using SolverHandle = std::unique_ptr<std::remove_pointer_t<HYPRE_Solver>, SolverDeleter>;

// A vector over this process's rows, in hypre's format so that the matrix and the V-cycle read
// it in place; the iteration works on its local values directly.
struct WorkVector {
  VectorHandle ij;
  HYPRE_ParVector par = nullptr;
  double* data = nullptr;
  int n = 0;

  WorkVector(MPI_Comm comm, int first, int count) : n(count) {
    HYPRE_IJVector v = nullptr;
    check(HYPRE_IJVectorCreate(comm, first, first + count - 1, &v), "IJVectorCreate");
    ij.reset(v);
    check(HYPRE_IJVectorSetObjectType(v, HYPRE_PARCSR), "IJVectorSetObjectType");
    check(HYPRE_IJVectorInitialize(v), "IJVectorInitialize");
    check(HYPRE_IJVectorAssemble(v), "IJVectorAssemble");
    void* object = nullptr;
    check(HYPRE_IJVectorGetObject(v, &object), "IJVectorGetObject");
    par = static_cast<HYPRE_ParVector>(object);
    data = hypre_VectorData(hypre_ParVectorLocalVector(par));
    std::fill(data, data + n, 0.0);
  }
  double* begin() const { return data; }
  double* end() const { return data + n; }
};

// A level's compressed rows out of hypre's (one process: every column is local).
CsrRows local_rows(hypre_ParCSRMatrix* m) {
  if (hypre_CSRMatrixNumCols(hypre_ParCSRMatrixOffd(m)) != 0)
    throw std::logic_error("a multigrid level on one process has columns of another");
  const hypre_CSRMatrix* d = hypre_ParCSRMatrixDiag(m);
  CsrRows rows;
  rows.n_rows = hypre_CSRMatrixNumRows(d);
  rows.n_cols = hypre_CSRMatrixNumCols(d);
  const HYPRE_Int* start = hypre_CSRMatrixI(d);
  rows.start.assign(start, start + rows.n_rows + 1);
  const HYPRE_Int* column = hypre_CSRMatrixJ(d);
  rows.column.assign(column, column + rows.start.back());
  const double* value = hypre_CSRMatrixData(d);
  rows.value.assign(value, value + rows.start.back());
  return rows;
}

// PFV's smoother for hypre's relax types, where it has one.
std::optional<MultigridSmoother> smoother_of(const AmgParameters& p) {
  if (p.relax_down == 13 && p.relax_up == 14) return MultigridSmoother::kSplitGaussSeidel;
  if (p.relax_down >= 0 || p.relax_up >= 0) return std::nullopt;
  if (p.relax_type == 18) return MultigridSmoother::kJacobi;
  if (p.relax_type == 8) return MultigridSmoother::kGaussSeidel;
  return std::nullopt;
}

}  // namespace

void ensure_hypre_initialized() {
  int running = 0;
  MPI_Initialized(&running);
  if (!running) {
    int provided = 0;
    // Threads other than the caller's never call MPI here (OpenMP loops only touch memory).
    if (MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS)
      throw std::runtime_error("MPI could not be initialised for the multigrid solver");
  }
  // hypre's own set-up, once per process (it holds no per-solver state).
  static std::once_flag once;
  std::call_once(once, [] { HYPRE_Init(); });
}

struct AmgPcg::Impl {
  MPI_Comm comm;
  int first = 0, n = 0;
  MatrixHandle ij;
  HYPRE_ParCSRMatrix a = nullptr;
  SolverHandle amg;
  // b, x and the iteration's residual, preconditioned residual, direction and G times it.
  mutable WorkVector b, x, r, z, p, q;
  SolutionHistory history;  // the last solutions, for the start of the next solve
  // On one process: the V-cycle and the products with G on PFV's threads (amg_cycle.hpp), and
  // hypre's matrix and hierarchy freed; on more, hypre's, on one thread per process.
  std::unique_ptr<AmgCycle> cycle;
  LoopChoice cycle_choice;    // the cycle on the team or on one thread, by time per iteration
  mutable bool team = false;  // cycle_choice's pick for this solve (only with kMinParallelLoop rows or more)

  Impl(MPI_Comm c, int first_row, int count, int kept_solutions)
      : comm(c),
        first(first_row),
        n(count),
        b(c, first_row, count),
        x(c, first_row, count),
        r(c, first_row, count),
        z(c, first_row, count),
        p(c, first_row, count),
        q(c, first_row, count),
        history(c, count, kept_solutions) {}

  // x <- the start from the history and x, the caller's start (solution_history.hpp).
  void start_from_history(double step) {
    if (history.adopt_start(x.data)) {
      multiply(x, q);  // G x, once per start the history lacks
      history.add(x.data, q.data, step);
    }
    history.predict(b.data, x.data, step);
  }

  void precondition() const {  // z = M^-1 r: one V-cycle from zero
    if (cycle) return cycle->apply(r.data, z.data, team);
    std::fill(z.begin(), z.end(), 0.0);
    HYPRE_BoomerAMGSolve(amg.get(), a, r.par, z.par);
  }
  void multiply(const WorkVector& in, WorkVector& out) const {  // out = G in
    if (cycle) return cycle->multiply(1.0, in.data, 0.0, out.data, team);
    HYPRE_ParCSRMatrixMatvec(1.0, a, in.par, 0.0, out.par);
  }
  void residual() const {  // r = b - G x
    std::copy(b.begin(), b.end(), r.begin());
    if (cycle) return cycle->multiply(-1.0, x.data, 1.0, r.data, team);
    HYPRE_ParCSRMatrixMatvec(-1.0, a, x.par, 1.0, r.par);
  }
  double dot(const WorkVector& u, const WorkVector& v) const {
    if (cycle) return fixed_chunk_dot(u.data, v.data, n, team);
    double d = 0;
    HYPRE_ParVectorInnerProd(u.par, v.par, &d);
    return d;
  }
  double residual_ratio() const {
    residual();
    const double bb = dot(b, b);
    return bb > 0 ? std::sqrt(dot(r, r) / bb) : std::sqrt(dot(r, r));
  }

  // The preconditioned CG iteration from x; `stop(k, alpha)` after each update of x.
  template <class Stop>
  int iterate(int max_iterations, Stop stop) const {
    residual();
    precondition();
    std::copy(z.begin(), z.end(), p.begin());
    double rz = dot(r, z);
    for (int k = 1; k <= max_iterations; ++k) {
      if (rz <= 0) return k - 1;  // r = 0: x is the solution
      multiply(p, q);
      const double pq = dot(p, q);
      if (!(pq > 0))
        throw std::domain_error(
            "the multigrid-preconditioned CG met a direction of non-positive "
            "curvature: the system is not positive definite");
      const double alpha = rz / pq;
#pragma omp parallel for schedule(static) if (team)
      for (int i = 0; i < n; ++i) {
        x.data[i] += alpha * p.data[i];
        r.data[i] -= alpha * q.data[i];
      }
      if (stop(k, alpha)) return k;
      precondition();
      const double next = dot(r, z);
      const double beta = next / rz;
      rz = next;
#pragma omp parallel for schedule(static) if (team)
      for (int i = 0; i < n; ++i) p.data[i] = z.data[i] + beta * p.data[i];
    }
    return -1;
  }
};

AmgPcg::AmgPcg(MPI_Comm comm, const DistributedRows& rows, const AmgParameters& parameters) {
  const int n = rows.n_local();
  if (n <= 0) throw std::invalid_argument("the multigrid solver needs at least one row per process");
  if (rows.column.size() != rows.value.size() || rows.row_start.front() != 0 ||
      rows.row_start.back() != static_cast<int>(rows.column.size()))
    throw std::invalid_argument("the rows given to the multigrid solver are inconsistent");
  for (int c : rows.column)
    if (c < 0 || c >= rows.global_rows) throw std::invalid_argument("a column index is outside the matrix");
  if (parameters.start_history < 0 || parameters.start_history > AmgParameters::kMaxStartHistory)
    throw std::invalid_argument("the multigrid solver keeps 0 to " + std::to_string(AmgParameters::kMaxStartHistory) +
                                " solutions for its start");
  ensure_hypre_initialized();
  impl_ = std::make_unique<Impl>(comm, rows.first_row, n, parameters.start_history);
  Impl& m = *impl_;

  HYPRE_IJMatrix ij = nullptr;
  const int last = rows.first_row + n - 1;
  check(HYPRE_IJMatrixCreate(comm, rows.first_row, last, rows.first_row, last, &ij), "IJMatrixCreate");
  m.ij.reset(ij);
  check(HYPRE_IJMatrixSetObjectType(ij, HYPRE_PARCSR), "IJMatrixSetObjectType");
  // Exact per-row sizes split into this process's columns (diag) and the others' (offd), so
  // that hypre allocates once.
  std::vector<HYPRE_Int> diag(n, 0), offd(n, 0), count(n), index(n);
  for (int i = 0; i < n; ++i) {
    count[i] = rows.row_start[i + 1] - rows.row_start[i];
    index[i] = rows.first_row + i;
    for (int e = rows.row_start[i]; e < rows.row_start[i + 1]; ++e)
      ++(rows.column[e] >= rows.first_row && rows.column[e] <= last ? diag[i] : offd[i]);
  }
  check(HYPRE_IJMatrixSetDiagOffdSizes(ij, diag.data(), offd.data()), "IJMatrixSetDiagOffdSizes");
  check(HYPRE_IJMatrixInitialize(ij), "IJMatrixInitialize");
  check(HYPRE_IJMatrixSetValues(ij, n, count.data(), index.data(), rows.column.data(), rows.value.data()),
        "IJMatrixSetValues");
  check(HYPRE_IJMatrixAssemble(ij), "IJMatrixAssemble");
  void* object = nullptr;
  check(HYPRE_IJMatrixGetObject(ij, &object), "IJMatrixGetObject");
  m.a = static_cast<HYPRE_ParCSRMatrix>(object);

  HYPRE_Solver amg = nullptr;
  check(HYPRE_BoomerAMGCreate(&amg), "BoomerAMGCreate");
  m.amg.reset(amg);
  HYPRE_BoomerAMGSetPrintLevel(amg, parameters.print_level);
  HYPRE_BoomerAMGSetMaxIter(amg, 1);  // one V-cycle per application: a preconditioner
  HYPRE_BoomerAMGSetTol(amg, 0.0);
  HYPRE_BoomerAMGSetStrongThreshold(amg, parameters.strong_threshold);
  HYPRE_BoomerAMGSetCoarsenType(amg, parameters.coarsen_type);
  HYPRE_BoomerAMGSetInterpType(amg, parameters.interp_type);
  HYPRE_BoomerAMGSetPMaxElmts(amg, parameters.max_row_entries);
  HYPRE_BoomerAMGSetRelaxType(amg, parameters.relax_type);
  HYPRE_BoomerAMGSetNumSweeps(amg, 1);
  if (parameters.relax_down >= 0) HYPRE_BoomerAMGSetCycleRelaxType(amg, parameters.relax_down, 1);
  if (parameters.relax_up >= 0) HYPRE_BoomerAMGSetCycleRelaxType(amg, parameters.relax_up, 2);
  HYPRE_BoomerAMGSetAggNumLevels(amg, parameters.aggressive_levels);
  check(HYPRE_BoomerAMGSetup(amg, m.a, m.b.par, m.x.par), "BoomerAMGSetup");
  auto* data = reinterpret_cast<hypre_ParAMGData*>(amg);
  levels_ = hypre_ParAMGDataNumLevels(data);
  const HYPRE_Int* relax = hypre_ParAMGDataGridRelaxType(data);
  relax_types_ = {static_cast<int>(relax[1]), static_cast<int>(relax[2])};  // [1] down, [2] up

  int processes = 1;
  MPI_Comm_size(comm, &processes);
  const std::optional<MultigridSmoother> smoother = smoother_of(parameters);
  if (processes == 1 && smoother && !parameters.hypre_cycle) {
    // PFV's cycle on the same hierarchy; hypre's copies go (the system's matrix too: the cycle
    // holds it), so the memory is that of hypre's solver alone.
    hypre_ParCSRMatrix** a_levels = hypre_ParAMGDataAArray(data);
    hypre_ParCSRMatrix** p_levels = hypre_ParAMGDataPArray(data);
    std::vector<CsrRows> a, p;
    for (int l = 0; l < levels_; ++l) {
      a.push_back(local_rows(a_levels[l]));
      if (l + 1 < levels_) p.push_back(local_rows(p_levels[l]));
    }
    m.cycle = std::make_unique<AmgCycle>(std::move(a), std::move(p), *smoother);
    operator_complexity_ = m.cycle->operator_complexity();
    m.amg.reset();
    m.a = nullptr;
    m.ij.reset();
    return;
  }
  // The operator complexity from hypre's own data: the entries of every level's matrix (global
  // counts, the same on every process) over those of G.
  hypre_ParCSRMatrix** a_levels = hypre_ParAMGDataAArray(data);
  double entries_g = 0, entries_all = 0;
  for (int l = 0; l < hypre_ParAMGDataNumLevels(data); ++l) {
    hypre_ParCSRMatrixSetNumNonzeros(a_levels[l]);
    const double e = static_cast<double>(hypre_ParCSRMatrixNumNonzeros(a_levels[l]));
    if (l == 0) entries_g = e;
    entries_all += e;
  }
  operator_complexity_ = entries_g > 0 ? entries_all / entries_g : 0;
}

AmgPcg::~AmgPcg() = default;

int AmgPcg::levels() const { return levels_; }

int AmgPcg::kept_solutions() const { return impl_->history.size(); }

std::array<int, 2> AmgPcg::cycle_relax_types() const { return relax_types_; }

AmgSolveStats AmgPcg::solve(const std::vector<double>& b, std::vector<double>& x, double tolerance, int max_iterations,
                            double step) {
  Impl& m = *impl_;
  if (static_cast<int>(b.size()) != m.n || static_cast<int>(x.size()) != m.n)
    throw std::invalid_argument("the multigrid solve needs one value of b and x per local row");
  std::copy(b.begin(), b.end(), m.b.begin());
  std::copy(x.begin(), x.end(), m.x.begin());
  m.team = m.cycle_choice.team(m.n);
  m.history.use_team(m.team);
  const auto t0 = StageClock::now();
  m.start_from_history(step);
  constexpr double kNegligibleUpdate = 1e-3, kSeedSafety = 2;
  // The first solve on a system goes on to kMeasuringTolerance at least, for a contraction
  // measured over enough iterations to hold for the later solves (a loose tolerance stops a solve
  // while its ratios are still those of the first updates, far below the contraction to come).
  constexpr double kMeasuringTolerance = 1e-8;
  if (seen_ratio_ == 0) tolerance = std::min(tolerance, kMeasuringTolerance);
  double previous = 0, largest = 0;
  int ratios = 0;  // since the estimate last started
  const auto stop = [&](int k, double alpha) {
    double d = 0, lo = m.x.data[0], hi = m.x.data[0], size = 0;
#pragma omp parallel for schedule(static) reduction(max : d, hi, size) reduction(min : lo) if (m.team)
    for (int i = 0; i < m.n; ++i) {
      d = std::max(d, std::abs(alpha * m.p.data[i]));
      lo = std::min(lo, m.x.data[i]);
      hi = std::max(hi, m.x.data[i]);
      size = std::max(size, std::abs(m.x.data[i]));
    }
    // One reduction for the three maxima: the update, -min x and max x (and max |x|).
    double local[4] = {d, -lo, hi, size}, global[4];
    MPI_Allreduce(local, global, 4, MPI_DOUBLE, MPI_MAX, m.comm);
    d = global[0];
    const double spread = global[1] + global[2] > 0 ? global[1] + global[2] : global[3];
    const double bound = tolerance * spread;
    if (k == 1) {
      // Only a contraction measured on this system certifies the first update, however small:
      // a start the history predicted well leaves a small update, which says nothing of the
      // error left in what the V-cycle reduces slowly.
      previous = d;
      // Twice the measured ratio, or halfway from it to 1 where that is less (a ratio of 1/2 or
      // more, as the Jacobi and split smoothers measure, would otherwise never let a first
      // update certify a step, however small).
      const double seed = std::min(kSeedSafety * seen_ratio_, 0.5 * (1 + seen_ratio_));
      return seed > 0 && seed < 1 && seed / (1 - seed) * d <= bound;
    }
    if (d <= kNegligibleUpdate * bound) return true;
    const double ratio = d / previous;
    previous = d;
    // An update larger than the one before: the iteration is not contracting (yet), so the
    // ratios so far say nothing about the error; the estimate starts again from the next one.
    largest = ratio < 1 ? std::max(largest, ratio) : 0;
    ratios = ratio < 1 ? ratios + 1 : 0;
    // One ratio alone is no estimate on a system without a measured one: the first ratio of a
    // solve is often far below the contraction that follows.
    if (ratios < 2 && seen_ratio_ == 0) return false;
    const double rho = largest > 0 ? std::max(largest, seen_ratio_) : 0;
    return rho > 0 && rho < 1 && rho / (1 - rho) * d <= bound;
  };
  AmgSolveStats stats;
  const int k = m.iterate(max_iterations, stop);
  stats.converged = k >= 0;
  stats.iterations = k >= 0 ? k : max_iterations;
  if (stats.iterations >= 3) seen_ratio_ = largest;
  m.history.add_provisional(m.x.data, m.b.data, m.r.data, step);
  m.cycle_choice.done(seconds_since(t0) / std::max(1, stats.iterations));
  std::copy(m.x.begin(), m.x.end(), x.begin());
  return stats;
}

AmgSolveStats AmgPcg::solve_to_residual(const std::vector<double>& b, std::vector<double>& x, double relative_residual,
                                        int max_iterations) const {
  const Impl& m = *impl_;
  if (static_cast<int>(b.size()) != m.n || static_cast<int>(x.size()) != m.n)
    throw std::invalid_argument("the multigrid solve needs one value of b and x per local row");
  std::copy(b.begin(), b.end(), m.b.begin());
  std::copy(x.begin(), x.end(), m.x.begin());
  const double target = relative_residual * std::sqrt(m.dot(m.b, m.b));
  const auto stop = [&](int, double) { return std::sqrt(m.dot(m.r, m.r)) <= target; };
  AmgSolveStats stats;
  const int k = target > 0 ? m.iterate(max_iterations, stop) : 0;
  if (target == 0) std::fill(m.x.begin(), m.x.end(), 0.0);
  stats.converged = k >= 0;
  stats.iterations = k >= 0 ? k : max_iterations;
  std::copy(m.x.begin(), m.x.end(), x.begin());
  stats.relative_residual = m.residual_ratio();
  return stats;
}

}  // namespace pfv
