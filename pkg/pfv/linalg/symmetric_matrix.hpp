// The operator of the linear solvers: a symmetric positive definite sparse matrix G, stored as
// its upper triangle compressed by column (row <= column, rows ascending within a column, so
// the diagonal entry closes each column). CHOLMOD (stype 1), CAMD and Eigen's upper views
// read this layout in place. Whoever assembles G fills it once; the solvers share it read-only
// (PressureSolver::setup keeps it for their solves).
#pragma once
#include <vector>

namespace pfv {

struct SymmetricMatrix {
  std::vector<int> col_start;  // size() + 1 entries
  std::vector<int> row;
  std::vector<double> value;

  int size() const { return col_start.empty() ? 0 : static_cast<int>(col_start.size()) - 1; }
};

}  // namespace pfv
