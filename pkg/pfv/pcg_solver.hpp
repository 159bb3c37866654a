// Conjugate gradient on G, preconditioned by an incomplete Cholesky factor computed once per
// remesh and warm-started from the previous pressures (useSolver=1, a PFV extension).
// Between remeshes the right-hand side changes little, so few iterations are needed.
#pragma once
#include <memory>
#include <vector>

namespace pfv {

struct PressureSystem;

class PcgSolver {
 public:
  PcgSolver();
  ~PcgSolver();
  PcgSolver(PcgSolver&&) noexcept;
  PcgSolver& operator=(PcgSolver&&) noexcept;

  void setup(const PressureSystem& system);
  bool ready() const;
  // x holds the initial guess and receives the solution; stops at |r| <= tolerance |b|.
  void solve(const std::vector<double>& rhs, std::vector<double>& x, double tolerance, int max_iterations);
  int iterations() const { return iterations_; }
  double error() const { return error_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int iterations_ = 0;
  double error_ = 0;
};

}  // namespace pfv
