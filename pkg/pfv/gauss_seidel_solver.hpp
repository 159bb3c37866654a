// Successive over-relaxation on the cell adjacency, warm-started from the previous
// pressures, stopped by the thesis' rule max|dp| / max|p| < tolerance (5.5).
#pragma once
#include <vector>

namespace pfv {

struct PressureSystem;

struct GaussSeidelResult {
  int iterations = 0;
  double relative_change = 0;
  bool converged = false;
};

// Updates the unknown entries of 'pressure' (indexed by cell) in place; 'rhs' is indexed by
// unknown and excludes the Dirichlet couplings, which are read from 'pressure'.
GaussSeidelResult gauss_seidel(const PressureSystem& s, const std::vector<double>& rhs,
                               std::vector<double>& pressure, double tolerance, double relax,
                               int max_iterations);

}  // namespace pfv
