#include "pfv/linalg/pressure_solver.hpp"

namespace pfv {

std::string_view to_string(SolverKind kind) {
  switch (kind) {
    case SolverKind::kGaussSeidel:
      return "gauss_seidel";
    case SolverKind::kConjugateGradient:
      return "conjugate_gradient";
    case SolverKind::kCholesky:
      return "cholesky";
    case SolverKind::kMultigrid:
      return "multigrid";
    case SolverKind::kAuto:
      return "auto";
  }
  return "unknown";
}

std::string_view to_string(MultigridSmoother smoother) {
  switch (smoother) {
    case MultigridSmoother::kGaussSeidel:
      return "gauss_seidel";
    case MultigridSmoother::kJacobi:
      return "jacobi";
    case MultigridSmoother::kSplitGaussSeidel:
      return "split_gauss_seidel";
  }
  return "unknown";
}

}  // namespace pfv
