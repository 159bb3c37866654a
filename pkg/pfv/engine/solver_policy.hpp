// The solver policy: which pressure solver a linear system gets, and what a remesh carries to
// the next one. Every rule of solver = auto lives here:
//  - choose: the Cholesky factor when it fits its budget (max_factor_bytes, else half the
//    memory available) and CHOLMOD's 32-bit index range, and when its step costs less than
//    multigrid's by the cost model (solver_cost.hpp: its set-up spread over the steps a system
//    serves, multigrid's iterations per step as seen on the last system); else multigrid. The
//    analysis that measures the factor is all a refused factor costs;
//  - keep: a multigrid solver chosen for the last mesh stays chosen for the next (a mesh of a
//    like size) while the budget is unchanged and, where the cost chose it, while the factor the
//    analysis projected then still costs more by the history seen since, without the ordering
//    and analysis that would only confirm it; a background remesh gets an empty multigrid solver
//    standing for it;
//  - recycle: a remesh hands the released solver (with the storage of its factor's values) to
//    the next system, so that peak memory is one factor and no new pages are faulted.
// A named solver is taken as asked (a named Cholesky refuses a factor beyond its bound with an
// error). Multigrid exists only in a build with hypre (PFV_WITH_HYPRE); without it asking for
// it is an error and auto never takes it.
#pragma once
#include <memory>
#include <string>

#include "pfv/common/stage_timer.hpp"
#include "pfv/engine/engine_settings.hpp"
#include "pfv/engine/solver_cost.hpp"
#include "pfv/linalg/pressure_solver.hpp"
#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

struct LinearSystem;

// Empty if this build has the solver, else why not (an unknown kind, or multigrid without hypre).
std::string solver_unavailable(SolverKind kind);
// A new solver of this kind, not set up (kAuto: the Cholesky factor). Throws
// std::invalid_argument (solver_unavailable's message) for multigrid in a build without hypre.
std::unique_ptr<PressureSolver> make_solver(SolverKind kind);

// Whether a system built for 'solver' must be rebuilt when the multigrid smoother changes (under
// kAuto also while it keeps the factor: the recipe does not know the choice).
bool reads_multigrid_smoother(SolverKind solver);

// The solver of a new system before its setup: the recycled one if it is of the kind the
// settings ask for (under kAuto, a Cholesky solver or a multigrid one kept), else a new one.
struct SolverPlan {
  std::unique_ptr<PressureSolver> solver;
  bool automatic = false;  // settings.solver is kAuto
  double budget = 0;       // factor values allowed (Cholesky and kAuto); infinity: no bound known
  SolveHistory history;    // kAuto: what the cost model weighs
};
SolverPlan plan_solver(const EngineSettings& settings, std::unique_ptr<PressureSolver> recycled,
                       const SolveHistory& history = {});

// The options of every solver from the settings; the factor's given ordering is the caller's.
SolverOptions solver_options(const EngineSettings& settings, const SolverPlan& plan);

// What set_up_solver decided under kAuto, for reports and for the next system's choice.
struct SolverDecision {
  std::string choice;        // the solver and why ("multigrid: the Cholesky factor would store ...")
  double analysis = 0;       // for a refused factor, the seconds from 'start' to the refusal
  double factor_values = 0;  // the values the analysis projected (0: no analysis)
  bool by_cost = false;      // multigrid chosen by the cost model, the factor fitting in memory
};

// Sets plan.solver up for g (at least one unknown) and returns it, with the decision. Throws
// what the solver's setup throws, and std::runtime_error if a Cholesky factor exceeds its bound
// with no fallback.
std::unique_ptr<PressureSolver> set_up_solver(SolverPlan plan, std::shared_ptr<const SymmetricMatrix> g,
                                              const SolverOptions& options, const EngineSettings& settings,
                                              StageClock::time_point start, SolverDecision& decision);

// Under kAuto: multigrid was chosen for 'current', the bound it was chosen against is unchanged
// and, if the cost model chose it, the factor projected then still costs more by 'history'; so
// the next system keeps it without an analysis.
bool auto_keeps_multigrid(const EngineSettings& settings, const LinearSystem& current, const SolveHistory& history);
// The current system's solver with what it built freed, for the next build (null if there is
// none, or if kAuto must choose again).
std::unique_ptr<PressureSolver> release_solver(const EngineSettings& settings, LinearSystem& current,
                                               const SolveHistory& history);
// What a background remesh, which cannot take the solver in use, passes to its build: an empty
// multigrid solver standing for it where kAuto keeps that choice (else null).
std::unique_ptr<PressureSolver> background_stand_in(bool keeps_multigrid);

}  // namespace pfv
