// The threshold below which a loop runs on one thread, shared by every layer that has
// OpenMP loops (pore geometry, assembly, forces, the refinement residual), and the number of
// threads a parallel region of the calling thread would get.
#pragma once
#ifdef _OPENMP
#include <omp.h>
#endif

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

}  // namespace pfv
