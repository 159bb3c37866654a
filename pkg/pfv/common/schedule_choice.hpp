// Picks one of a few schedules of a computation that give the same result to the bit, by the
// time each took on this machine: the parallel substitution's serial, two-group and shared-top
// schedules (parallel_substitution.hpp), and one thread or the team for the engine's loops over
// cells and spheres at each step (flow_engine.cpp).
//
// On free cores a team pays; on cores other processes hold, every barrier and every fork waits
// for a descheduled thread, up to a scheduler time slice each, and the schedule with the fewest
// of them wins whatever the work. Which case holds changes while a simulation runs, so the
// choice is measured, not assumed: each schedule is tried once, then the fastest is used and the
// others are tried again now and then, less often each time they lose (a losing schedule can be
// many times slower), again soon after one wins.
#pragma once
#include <array>

namespace pfv {

template <int N>
class ScheduleChoice {
 public:
  // The schedule for the next run, among the first 'available' (>= 1).
  int pick(int available) {
    for (int m = N - 1; m >= 0; --m)  // untried ones first, the most parallel first
      if (m < available && time_[m] < 0) return probing_ = m;
    const int best = best_of(available);
    if (--countdown_ > 0) return probing_ = best;
    countdown_ = interval_;
    next_probe_ = (next_probe_ + 1) % available;
    if (next_probe_ == best) next_probe_ = (next_probe_ + 1) % available;
    return probing_ = next_probe_;
  }
  // The run of pick()'s schedule took 'seconds'.
  void record(int available, double seconds) {
    const int m = probing_;
    const int best_before = time_[m] < 0 ? m : best_of(available);
    // The schedule in use follows the load smoothly; a probe's one sample stands for it.
    time_[m] = (m == best_before && time_[m] >= 0) ? 0.5 * (time_[m] + seconds) : seconds;
    if (m == best_before) return;
    if (best_of(available) == m)
      interval_ = kFirstInterval;  // the machine changed: look again soon
    else if (interval_ < kMaxInterval)
      interval_ *= 2;
  }
  void reset() { *this = ScheduleChoice{}; }

  static constexpr int kFirstInterval = 8, kMaxInterval = 1024;

 private:
  int best_of(int available) const {
    int best = 0;
    for (int m = 1; m < available; ++m)
      if (time_[m] >= 0 && (time_[best] < 0 || time_[m] < time_[best])) best = m;
    return best;
  }

  std::array<double, N> time_ = [] {
    std::array<double, N> t;
    t.fill(-1);
    return t;
  }();
  int probing_ = 0, countdown_ = kFirstInterval, interval_ = kFirstInterval, next_probe_ = 0;
};

}  // namespace pfv
