// The start of an iterative solve of G x = b from the solutions of the last solves with the same
// G: their extrapolation in time to the next step, of the order (constant, linear, quadratic, ...)
// whose residual b - G x is the smallest.
//
// Between remeshes G is fixed and b changes smoothly with the motion, so the pressures do too:
// with the spheres moving at constant velocities the cell volumes are cubic in time, the volume
// rates quadratic, and the quadratic extrapolation from the last three solutions misses the next
// by a third difference, far below the tolerance (a linear one misses it by a second difference).
// Which order holds is not known in advance: the first step has no volume rates, a boundary value
// may change, the motion may turn. Each order's residual says it, at no product with G: every
// kept solution keeps G x beside x (from the solve's residual, b - r, or one product when the
// caller hands in pressures the history lacks), and the residuals of the extrapolations are the
// same combinations of those products, formed entry by entry (b and G x agree to many digits).
// The extrapolation is in time (each solve gives the time since the last one, the DEM step), each
// solution placed in the middle of its step, where the backward difference of the volumes over the
// step is accurate to second order: a changed time step keeps the trend. (A projection onto the span of the solutions,
// the best start in the energy norm, is worse in the max norm than the plain extrapolation there, by a factor 20 to 100
// on a drifting lattice: it trades error in the rough modes, which carry the energy, for smooth error, which carries
// the max norm the stopping rule bounds.)
//
// MPI: every rank holds its rows of the vectors; the reductions run over the communicator.
#pragma once
#include <mpi.h>

#include <vector>

namespace pfv {

class SolutionHistory {
 public:
  SolutionHistory(MPI_Comm comm, int n, int capacity);

  int size() const { return count_; }
  // Whether the passes over the rows may run on the calling thread's team (from
  // kMinParallelLoop rows; the same bits either way).
  void use_team(bool team) { team_ = team; }
  int capacity() const { return static_cast<int>(x_.size()); }
  void clear() { count_ = 0, provisional_ = false; }

  // The caller's start of the next solve: the pressures it kept from the last step it accepted. If
  // that is the solution added provisionally by the last solve, the entry is confirmed; otherwise
  // (the caller dropped that step, or changed its pressures) the entry is removed. Returns true if
  // the start is none of the kept solutions and not zero: the caller then adds it with its product
  // with G (add()). Collective.
  bool adopt_start(const double* start);
  // x and G x, as the newest entry, at the instant of the newest (the oldest goes once capacity()
  // are kept), the solution of a step of this length (the caller's last step; taken as the next).
  void add(const double* x, const double* gx, double step);
  // The solution of a solve just finished, step after the newest entry, with G x = b - r (r its
  // residual): the newest entry until adopt_start() finds the next start is not it. Entries that
  // are not finite are not kept.
  void add_provisional(const double* x, const double* b, const double* r, double step);
  // x <- the extrapolation of the entries to step after the newest whose residual with b is the
  // smallest; returns its order (0: the newest entry), or -1 with no entry or residuals that are
  // not finite (x is then unchanged, and the history cleared). Collective.
  int predict(const double* b, double* x, double step);

 private:
  const std::vector<double>& newest() const { return x_[head_]; }
  bool equals_newest(const double* v) const;  // collective
  bool on_team() const;
  void drop_newest();

  MPI_Comm comm_;
  int n_;
  std::vector<std::vector<double>> x_, gx_;  // a ring, the newest at head_
  // The end of each entry's step, from the first kept, and the step. A solution stands for the
  // middle of its step: the volume rates are differences over the step.
  std::vector<double> time_, step_;
  int head_ = 0, count_ = 0;
  bool provisional_ = false;
  bool team_ = false;
};

}  // namespace pfv
