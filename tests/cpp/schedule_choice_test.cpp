// The choice among equivalent schedules by their measured times: each is tried once, then the
// fastest runs, the others are tried again less often while they lose, and a schedule that has
// become the fastest (the machine's load changed) takes over.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pfv/common/parallel.hpp"
#include "pfv/common/schedule_choice.hpp"

using pfv::kMinParallelLoop;
using pfv::LoopChoice;
using pfv::ScheduleChoice;

namespace {

// Runs 'runs' picks with the given time per schedule; returns how often each ran.
std::array<int, 3> run(ScheduleChoice<3>& c, int available, const std::array<double, 3>& seconds, int runs) {
  std::array<int, 3> count{};
  for (int k = 0; k < runs; ++k) {
    const int m = c.pick(available);
    EXPECT_GE(m, 0);
    EXPECT_LT(m, available);
    ++count[m];
    c.record(available, seconds[m]);
  }
  return count;
}

}  // namespace

TEST(ScheduleChoice, TriesEachOnceThenKeepsTheFastest) {
  ScheduleChoice<3> c;
  std::vector<int> first;
  for (int k = 0; k < 3; ++k) {
    first.push_back(c.pick(3));
    c.record(3, k == 1 ? 1.0 : 5.0);  // the second tried is the fastest
  }
  EXPECT_EQ(first, (std::vector<int>{2, 1, 0}));  // the most parallel first
  EXPECT_EQ(c.pick(3), 1);
}

TEST(ScheduleChoice, ALosingScheduleIsTriedLessAndLessOften) {
  ScheduleChoice<3> c;
  // The shared schedule far slower, as on cores other processes hold.
  const auto count = run(c, 3, {1.0, 0.8, 30.0}, 2000);
  EXPECT_GT(count[1], 1950);
  EXPECT_GE(count[2], 2);   // tried again now and then
  EXPECT_LE(count[2], 12);  // with the interval doubling from 8 up to 1024
}

TEST(ScheduleChoice, AScheduleThatBecomesFastestTakesOver) {
  ScheduleChoice<3> c;
  run(c, 3, {1.0, 2.0, 3.0}, 50);                       // serial fastest (loaded cores)
  const auto count = run(c, 3, {1.0, 2.0, 0.4}, 2000);  // the cores are free again
  EXPECT_GT(count[2], 1900);
}

TEST(ScheduleChoice, OnlyTheAvailableSchedules) {
  ScheduleChoice<3> c;
  const auto count = run(c, 2, {1.0, 0.5, 0.1}, 100);  // no shared top: schedule 2 never runs
  EXPECT_EQ(count[2], 0);
  EXPECT_GT(count[1], 90);
}

#ifdef _OPENMP
// Sets the calling thread's OpenMP thread count while in scope.
class ThreadCount {
 public:
  explicit ThreadCount(int n) : before_(omp_get_max_threads()) { omp_set_num_threads(n); }
  ~ThreadCount() { omp_set_num_threads(before_); }
  ThreadCount(const ThreadCount&) = delete;
  ThreadCount& operator=(const ThreadCount&) = delete;

 private:
  int before_;
};
#endif

TEST(LoopChoice, ATeamOnlyForLongLoopsOnSeveralThreads) {
#ifdef _OPENMP
  const ThreadCount one_thread(1);
#endif
  LoopChoice c;
  for (int k = 0; k < 20; ++k) {
    EXPECT_FALSE(c.team(10 * kMinParallelLoop));  // one thread: nothing to choose
    c.done(1.0);
  }
#ifdef _OPENMP
  const ThreadCount two_threads(2);
  LoopChoice d;
  for (int k = 0; k < 20; ++k) {
    EXPECT_FALSE(d.team(kMinParallelLoop));  // too short to pay
    d.done(1.0);
  }
  // Long loops: the team is tried first; a team three times slower (busy cores) then loses.
  int teams = 0;
  for (int k = 0; k < 200; ++k) {
    const bool team = d.team(10 * kMinParallelLoop);
    teams += team;
    d.done(team ? 3.0 : 1.0);
  }
  EXPECT_GE(teams, 1);
  EXPECT_LE(teams, 20);
#endif
}
