// Runs the OpenMP regions of a library call on the calling thread alone.
//
// Debian 12's CHOLMOD 3 is built with CHOLMOD_OMP_NUM_THREADS = 4 and asks for teams of that
// size in its supernodal numeric factorisation, whatever omp_set_num_threads says. Those teams
// only copy and scatter small blocks, so on a 2-core machine they cost far more than they
// save: the factorisation takes about twice as long with them (bench/solver_stages.py
// --sections=5; doc/benchmarks.md). Debian's default BLAS (openblas-pthread) keeps its own
// threads underneath; an OpenMP build of OpenBLAS would be capped to one thread here too.
//
// With dynamic adjustment on and nthreads-var = 1, libgomp caps every region to one thread,
// num_threads clauses included. Both are per-thread settings (they belong to the calling
// thread's task), so YADE's own OpenMP loops, or the DEM thread while a background remesh
// factorises, are not affected.
#pragma once
#ifdef _OPENMP
#include <omp.h>
#endif

namespace pfv {

class SerialOpenMpRegions {
 public:
#ifdef _OPENMP
  SerialOpenMpRegions() : dynamic_(omp_get_dynamic()), threads_(omp_get_max_threads()) {
    omp_set_dynamic(1);
    omp_set_num_threads(1);
  }
  ~SerialOpenMpRegions() {
    omp_set_num_threads(threads_);
    omp_set_dynamic(dynamic_);
  }
#else
  SerialOpenMpRegions() = default;
#endif
  SerialOpenMpRegions(const SerialOpenMpRegions&) = delete;
  SerialOpenMpRegions& operator=(const SerialOpenMpRegions&) = delete;

 private:
#ifdef _OPENMP
  int dynamic_, threads_;
#endif
};

}  // namespace pfv
