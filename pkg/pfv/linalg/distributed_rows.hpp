// Rows of a symmetric positive definite matrix as one process of a distributed solve holds
// them (the multigrid solver, amg_pcg.hpp; a system saved to disk, system_io.hpp): full rows,
// both triangles, compressed by row with global column indices. Plain arrays, no MPI.
#pragma once
#include <vector>

#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

// Rows first_row .. first_row + n - 1.
struct DistributedRows {
  long long global_rows = 0;
  int first_row = 0;
  std::vector<int> row_start;  // n + 1 entries
  std::vector<int> column;
  std::vector<double> value;

  int n_local() const { return row_start.empty() ? 0 : static_cast<int>(row_start.size()) - 1; }
};

// G's full rows (both triangles) from its stored upper triangle: one process's whole matrix.
DistributedRows full_rows(const SymmetricMatrix& g);

}  // namespace pfv
