// The threshold below which a loop runs on one thread, shared by every layer that has
// OpenMP loops (pore geometry, assembly, forces, the refinement residual).
#pragma once

namespace pfv {

// Loops shorter than this run on one thread: waking a thread team costs more than the loop,
// and far more when the cores are shared with other processes.
constexpr int kMinParallelLoop = 20000;

}  // namespace pfv
