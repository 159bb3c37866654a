// A pressure system on disk, for solvers run outside the engine (bench/amg/amg_solve.cpp solves
// one over MPI): G as a Matrix Market coordinate file (symmetric, lower triangle), the right-hand
// side b and the engine's solution x as Matrix Market arrays, in one folder:
// G.mtx, b.mtx, x.mtx. Plain text in full precision (17 significant digits), so a file read back
// gives the same doubles.
#pragma once
#include <string>
#include <vector>

#include "pfv/linalg/distributed_rows.hpp"
#include "pfv/linalg/symmetric_matrix.hpp"

namespace pfv {

// Throws std::runtime_error if a file cannot be written, std::invalid_argument if b or x do
// not have one value per unknown.
void write_system(const std::string& folder, const SymmetricMatrix& g, const std::vector<double>& b,
                  const std::vector<double>& x);

// Rows first .. first + count - 1 of a saved system with the same rows of b and x.
struct SavedRows {
  DistributedRows rows;
  std::vector<double> b, x;
};

// Number of unknowns of the system saved in folder.
long long saved_system_size(const std::string& folder);
// Throws std::runtime_error on a missing or malformed file.
SavedRows read_system_rows(const std::string& folder, int first, int count);

}  // namespace pfv
