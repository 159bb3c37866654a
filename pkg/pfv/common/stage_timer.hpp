// Wall-clock timing of the pipeline's stages (FlowEngine::remesh_times / step_times).
#pragma once
#include <chrono>

namespace pfv {

using StageClock = std::chrono::steady_clock;

inline double seconds_since(StageClock::time_point t0) {
  return std::chrono::duration<double>(StageClock::now() - t0).count();
}

}  // namespace pfv
