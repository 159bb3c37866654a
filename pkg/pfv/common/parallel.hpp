// The threshold below which a loop runs on one thread, shared by every layer that has
// OpenMP loops (pore geometry, assembly, forces, the refinement residual), and the number of
// threads a parallel region of the calling thread would get.
#pragma once
#ifdef _OPENMP
#include <omp.h>
#endif

#include "pfv/common/schedule_choice.hpp"

namespace pfv {

// Loops shorter than this run on one thread: waking a thread team costs more than the loop,
// and far more when the cores are shared with other processes.
constexpr int kMinParallelLoop = 20000;

// omp_get_max_threads(), or 1 in a build without OpenMP.
inline int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// Sums over a range that may run on a team are added over this many fixed chunks, in order: the
// same bits on one thread as on a team of any size (the step's sums over cells, the multigrid
// solve's dot products and its history's residuals).
constexpr int kSumChunks = 64;

// The first index of chunk k of [0, n) (chunk kSumChunks ends at n).
inline int chunk_begin(long long n, int k) { return static_cast<int>(n * k / kSumChunks); }

// One thread or the team for a loop run at every step, by the time each took (ScheduleChoice):
// on free cores the team pays from kMinParallelLoop items on, on cores other processes hold the
// fork and join wait for a descheduled thread and one thread is many times faster. The loop must
// give the same bits either way.
class LoopChoice {
 public:
  // Whether this run of a loop of 'items' goes to the team; then done() with its time.
  bool team(long items) {
    measured_ = items > kMinParallelLoop && max_threads() > 1;
    return measured_ && choice_.pick(2) == 1;
  }
  void done(double seconds) {
    if (measured_) choice_.record(2, seconds);
  }

 private:
  ScheduleChoice<2> choice_;
  bool measured_ = false;
};

}  // namespace pfv
