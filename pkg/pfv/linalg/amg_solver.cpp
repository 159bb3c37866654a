#include "pfv/linalg/amg_solver.hpp"

#include "pfv/model/pressure_system.hpp"

namespace pfv {

DistributedRows full_rows(const PressureSystem& s) {
  const int n = s.n_unknowns();
  DistributedRows rows;
  rows.global_rows = n;
  rows.row_start.assign(n + 1, 0);
  for (int j = 0; j < n; ++j)
    for (int e = s.col_start[j]; e < s.col_start[j + 1]; ++e) {
      ++rows.row_start[s.row[e] + 1];
      if (s.row[e] != j) ++rows.row_start[j + 1];
    }
  for (int i = 0; i < n; ++i) rows.row_start[i + 1] += rows.row_start[i];
  rows.column.resize(rows.row_start[n]);
  rows.value.resize(rows.row_start[n]);
  std::vector<int> next(rows.row_start.begin(), rows.row_start.end() - 1);
  // Entry (i, j <= i) of a column j is written to rows i and j (hypre sorts no columns and
  // needs none sorted).
  for (int j = 0; j < n; ++j)
    for (int e = s.col_start[j]; e < s.col_start[j + 1]; ++e) {
      const int i = s.row[e];
      rows.column[next[i]] = j;
      rows.value[next[i]++] = s.value[e];
      if (i != j) {
        rows.column[next[j]] = i;
        rows.value[next[j]++] = s.value[e];
      }
    }
  return rows;
}

void AmgSolver::setup(const PressureSystem& system, const AmgParameters& parameters) {
  pcg_.reset();
  pcg_ = std::make_unique<AmgPcg>(MPI_COMM_SELF, full_rows(system), parameters);
}

SolveStats AmgSolver::solve(const PressureSystem&, const std::vector<double>& b, std::vector<double>& x,
                            const SolveControl& control) {
  const AmgSolveStats s = pcg_->solve(b, x, control.refinement_tolerance, control.max_iterations);
  SolveStats stats;
  stats.cg_iterations = s.iterations;
  stats.converged = s.converged;
  return stats;
}

void AmgSolver::apply_inverse(const PressureSystem& system, const std::vector<double>& b, std::vector<double>& x,
                              const SolveControl& control) const {
  x.assign(system.n_unknowns(), 0.0);
  pcg_->solve_to_residual(b, x, control.inverse_tolerance, control.max_iterations);
}

}  // namespace pfv
