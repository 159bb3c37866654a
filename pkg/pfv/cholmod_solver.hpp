// Sparse Cholesky of G with CHOLMOD: analysed and factorised once per remesh, then only
// forward/back substitution each step, into buffers allocated at factorisation.
// Owns every CHOLMOD object it creates (YADE leaked factors here).
#pragma once
#include <vector>

#include "parallel_substitution.hpp"

namespace pfv {

struct PressureSystem;

// Fill-reducing ordering. kAuto is CHOLMOD's default (AMD, then METIS if AMD fills badly).
enum class Ordering { kAuto, kAmd, kMetis, kNestedDissection };

class CholmodSolver {
 public:
  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  // Throws std::domain_error if G is not positive definite.
  void factorize(const PressureSystem& system, Ordering ordering);
  // With two or more OpenMP threads the substitutions run on subtrees in parallel
  // (parallel_substitution.hpp); with one, CHOLMOD's own (BLAS-based) solve is used.
  void solve(const std::vector<double>& rhs, std::vector<double>& x);
  void solve_serial(const std::vector<double>& rhs, std::vector<double>& x);
  double parallel_top_fraction() const { return parallel_.top_fraction(); }
  bool metis_used() const { return metis_used_; }
  bool ready() const { return factor_ != nullptr; }
  double factor_nonzeros() const;
  double factor_flops() const;
  double analysis_seconds() const { return analysis_seconds_; }  // ordering + symbolic

 private:
  void release();
  struct Common;
  Common* common_;
  void* factor_ = nullptr;  // cholmod_factor*
  void* rhs_ = nullptr;     // cholmod_dense*, reused
  void* x_ = nullptr;
  void* work_y_ = nullptr;
  void* work_e_ = nullptr;
  ParallelSubstitution parallel_;
  bool metis_used_ = false;
  double analysis_seconds_ = 0;
};

}  // namespace pfv
