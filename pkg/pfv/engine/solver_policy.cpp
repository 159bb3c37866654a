#include "pfv/engine/solver_policy.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "pfv/common/stage_timer.hpp"
#include "pfv/engine/linear_system.hpp"
#include "pfv/linalg/cholesky_solver.hpp"
#include "pfv/linalg/gauss_seidel_solver.hpp"
#include "pfv/linalg/pcg_solver.hpp"
#if PFV_WITH_HYPRE
#include "pfv/linalg/amg_solver.hpp"
#endif

namespace pfv {
namespace {

constexpr bool kMultigridBuilt = PFV_WITH_HYPRE;

// MemAvailable of /proc/meminfo in bytes (the kernel's estimate of what can be allocated
// without swapping); 0 if unreadable.
double memory_available() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kib = 0;
  std::string unit;
  while (in >> key >> kib >> unit)
    if (key == "MemAvailable:") return kib * 1024;
  return 0;
}

// Whether a factor beyond its bound leaves multigrid in its place (kAuto in a build with hypre)
// rather than an error.
bool falls_back(const EngineSettings& s) { return s.solver == SolverKind::kAuto && kMultigridBuilt; }

// The bound on the values of a Cholesky factor: where it falls back, the size beyond which it
// takes multigrid (half the memory available, by default); else, beyond which the factor is
// refused with an error (all of it: values that alone could not be stored).
double factor_entry_budget(const EngineSettings& s, const PressureSolver* recycled) {
  double bytes = s.max_factor_bytes;
  if (bytes == 0) {
    const double available = memory_available();
    if (available == 0) return std::numeric_limits<double>::infinity();  // not known: no bound
    bytes = (falls_back(s) ? 0.5 : 1.0) * available;
    if (const auto* c = dynamic_cast<const CholeskySolver*>(recycled))
      bytes += static_cast<double>(c->factor().value_capacity()) * sizeof(double);  // reused, not new
  }
  return bytes / sizeof(double);
}

// Four significant digits: a factor and the budget it is compared with may agree to three.
std::string bytes_text(double bytes) {
  char text[32];
  if (bytes >= 1e9)
    std::snprintf(text, sizeof text, "%.4g GB", bytes / 1e9);
  else
    std::snprintf(text, sizeof text, "%.4g MB", bytes / 1e6);
  return text;
}

// "the Cholesky factor would store ..., more than ...": why a factor was refused.
std::string refusal_text(const FactorTooLarge& e, const EngineSettings& s) {
  if (e.why == FactorLimit::kIndexRange) {
    char values[32];
    std::snprintf(values, sizeof values, "%.3g", e.entries);
    return std::string("the Cholesky factor would store at least ") + values +
           " values, more than the 2^31 - 1 that CHOLMOD's 32-bit indices address";
  }
  const std::string limit = falls_back(s)            ? "the budget of " + bytes_text(e.limit * 8)
                            : s.max_factor_bytes > 0 ? "max_factor_bytes = " + bytes_text(e.limit * 8)
                                                     : "the " + bytes_text(e.limit * 8) + " of memory available";
  return "the Cholesky factor would store " + bytes_text(e.entries * 8) + ", more than " + limit;
}

// " beyond which multigrid's step costs less (2 CG iterations per step, 1000 steps per system)"
std::string cost_text(const CostInputs& c) {
  char text[160];
  std::snprintf(text, sizeof text,
                " beyond which multigrid's step costs less (%.3g CG iterations per step, %.4g steps per system)",
                c.iterations, c.steps_per_system);
  return text;
}

}  // namespace

std::unique_ptr<PressureSolver> make_solver(SolverKind kind) {
  switch (kind) {
    case SolverKind::kGaussSeidel:
      return std::make_unique<GaussSeidelSolver>();
    case SolverKind::kConjugateGradient:
      return std::make_unique<PcgSolver>();
    case SolverKind::kMultigrid:
#if PFV_WITH_HYPRE
      return std::make_unique<AmgSolver>();
#else
      throw std::invalid_argument(solver_unavailable(kind));
#endif
    case SolverKind::kCholesky:
    case SolverKind::kAuto:
      break;
  }
  return std::make_unique<CholeskySolver>();
}

std::string solver_unavailable(SolverKind kind) {
  switch (kind) {
    case SolverKind::kGaussSeidel:
    case SolverKind::kConjugateGradient:
    case SolverKind::kCholesky:
    case SolverKind::kAuto:
      return {};
    case SolverKind::kMultigrid:
      if (kMultigridBuilt) return {};
      return "solver='multigrid': PFV was built without hypre (PFV_WITH_HYPRE=OFF), so it has no multigrid "
             "solver; rebuild with hypre and MPI, or use 'cholesky', 'conjugate_gradient' or 'auto'";
  }
  return "solver must be Gauss-Seidel, conjugate gradients, Cholesky, multigrid or auto";
}

bool reads_multigrid_smoother(SolverKind solver) {
  return solver == SolverKind::kMultigrid || solver == SolverKind::kAuto;
}

SolverPlan plan_solver(const EngineSettings& settings, std::unique_ptr<PressureSolver> recycled,
                       const SolveHistory& history) {
  SolverPlan plan;
  plan.history = history;
  // Under kAuto a multigrid solver carried over keeps the choice made for the earlier mesh of
  // this engine (of a like size): every analysis that would only confirm it costs an ordering.
  plan.automatic = settings.solver == SolverKind::kAuto;
  const bool keep =
      recycled &&
      (recycled->kind() == settings.solver ||
       (plan.automatic && (recycled->kind() == SolverKind::kCholesky || recycled->kind() == SolverKind::kMultigrid)));
  const bool factor = plan.automatic || settings.solver == SolverKind::kCholesky;
  plan.budget = factor ? factor_entry_budget(settings, recycled.get()) : 0;
  plan.solver = keep ? std::move(recycled) : make_solver(settings.solver);
  return plan;
}

SolverOptions solver_options(const EngineSettings& settings, const SolverPlan& plan) {
  SolverOptions options;
  options.factor.ordering = settings.factor_ordering();
  options.factor.precision = settings.mixed_precision ? FactorPrecision::kScaled32 : FactorPrecision::kDouble;
  options.factor.min_scaled_entries = settings.mixed_precision_min_entries;
  options.factor.openmp_teams = settings.cholmod_openmp_teams;
  options.factor.max_entries = plan.budget;
  options.multigrid_smoother = settings.multigrid_smoother;
  return options;
}

std::unique_ptr<PressureSolver> set_up_solver(SolverPlan plan, std::shared_ptr<const SymmetricMatrix> g,
                                              const SolverOptions& options, const EngineSettings& settings,
                                              StageClock::time_point start, SolverDecision& decision) {
  std::unique_ptr<PressureSolver> solver = std::move(plan.solver);
  if (solver->kind() == SolverKind::kCholesky) {
    // Under kAuto the factor must also cost less per step than multigrid: a bound on its values
    // that CHOLMOD's analysis checks like the memory budget.
    const bool weighs_cost = falls_back(settings);
    const CostInputs cost = cost_inputs(g->size(), plan.history, settings);
    const double cost_bound = weighs_cost ? break_even_factor_values(cost) : std::numeric_limits<double>::infinity();
    SolverOptions bounded = options;
    bounded.factor.max_entries = std::min(options.factor.max_entries, cost_bound);
    try {
      solver->setup(g, bounded);
      decision.factor_values = static_cast<const CholeskySolver&>(*solver).factor().factor_nonzeros();
      if (plan.automatic)
        decision.choice = "cholesky: the factor stores " + bytes_text(decision.factor_values * 8) +
                          ", within the budget of " + bytes_text(plan.budget * 8) + " and below the " +
                          bytes_text(cost_bound * 8) + cost_text(cost);
      return solver;
    } catch (const FactorTooLarge& e) {
      if (!falls_back(settings))
        throw std::runtime_error(
            "solver='" + std::string(to_string(settings.solver)) + "': " + refusal_text(e, settings) +
            (kMultigridBuilt ? "; use solver='multigrid' (or 'auto', which takes it when the factor does not fit)"
                             : "; PFV was built without hypre (PFV_WITH_HYPRE=OFF): no multigrid solver to take"));
      decision.factor_values = e.entries;
      decision.by_cost = e.why == FactorLimit::kBudget && e.entries <= plan.budget;
      decision.choice = decision.by_cost ? "multigrid: the Cholesky factor would store " + bytes_text(e.entries * 8) +
                                               ", more than the " + bytes_text(cost_bound * 8) + cost_text(cost)
                                         : "multigrid: " + refusal_text(e, settings);
      solver = make_solver(SolverKind::kMultigrid);
      decision.analysis = seconds_since(start);
    }
  }
  if (plan.automatic && decision.choice.empty()) {  // kept: the last choice stands
    decision.choice = "multigrid: kept from the previous mesh";
    decision.factor_values = plan.history.factor_values;
    decision.by_cost = plan.history.multigrid_by_cost;
  }
  solver->setup(std::move(g), options);
  return solver;
}

bool auto_keeps_multigrid(const EngineSettings& settings, const LinearSystem& current, const SolveHistory& history) {
  if (settings.solver != SolverKind::kAuto || !current.solver || current.solver->kind() != SolverKind::kMultigrid ||
      current.recipe.max_factor_bytes != settings.max_factor_bytes)
    return false;
  if (!current.decision.by_cost) return true;  // the memory refused the factor: it still would
  // The factor projected then, weighed again with what the last system's solves showed.
  const CostInputs cost = cost_inputs(current.system.n_unknowns(), history, settings);
  return current.decision.factor_values > break_even_factor_values(cost);
}

std::unique_ptr<PressureSolver> release_solver(const EngineSettings& settings, LinearSystem& current,
                                               const SolveHistory& history) {
  // Under kAuto a multigrid solver carried over keeps the choice (plan_solver); a new
  // max_factor_bytes, or a history that makes the factor cheaper, asks for it again.
  const bool drop = settings.solver == SolverKind::kAuto && current.solver &&
                    current.solver->kind() == SolverKind::kMultigrid &&
                    !auto_keeps_multigrid(settings, current, history);
  auto solver = std::move(current.solver);
  if (solver) solver->release();
  if (drop) solver.reset();
  return solver;
}

std::unique_ptr<PressureSolver> background_stand_in(bool keeps_multigrid) {
  return keeps_multigrid ? make_solver(SolverKind::kMultigrid) : nullptr;
}

}  // namespace pfv
