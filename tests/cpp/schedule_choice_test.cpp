// The choice among equivalent schedules by their measured times: each is tried once, then the
// fastest runs, the others are tried again less often while they lose, and a schedule that has
// become the fastest (the machine's load changed) takes over.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pfv/linalg/schedule_choice.hpp"

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
