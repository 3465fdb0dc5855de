#include "sensors/replay_end.h"

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

// A replay whose clock runs from wall 1 s to 10 s, then stands still (the bag ended).
ReplayEnd Played(const ReplayEndOptions& o) {
  ReplayEnd end(o, 0.0);
  for (double wall = 1.0; wall <= 10.0; wall += 0.5) end.Clock(1700000000.0 + wall, wall);
  return end;
}

TEST(ReplayEndTest, OverOnceTheClockAndTheInputsStandStill) {
  ReplayEndOptions o;
  ReplayEnd end = Played(o);
  EXPECT_EQ(end.Check(10.0, 0), ReplayVerdict::kRunning);
  EXPECT_EQ(end.Check(14.9, 0), ReplayVerdict::kRunning);
  EXPECT_EQ(end.Check(15.1, 0), ReplayVerdict::kOver);
  // A clip flushed after the clock stopped (the clip buffer's flush_after) holds it off.
  end.Activity(13.0);
  EXPECT_EQ(end.Check(15.1, 0), ReplayVerdict::kRunning);
  EXPECT_EQ(end.Check(18.1, 0), ReplayVerdict::kOver);
}

// sdn_node still working through its queue: the report waits up to estimate_wait more for the
// estimates (a model slower than idle_timeout a clip had its backlog cut off), each estimate
// holding it off again.
TEST(ReplayEndTest, ClipsWithoutTheirEstimateAreWaitedFor) {
  ReplayEndOptions o;
  o.estimate_wait = 30.0;
  ReplayEnd end = Played(o);
  EXPECT_EQ(end.Check(16.0, 3), ReplayVerdict::kRunning);
  end.Activity(20.0);  // one more estimate
  EXPECT_EQ(end.Check(50.0, 2), ReplayVerdict::kRunning);
  EXPECT_EQ(end.Check(55.1, 2), ReplayVerdict::kOver);  // 20 + 5 + 30: the rest never came
  EXPECT_EQ(end.Check(25.1, 0), ReplayVerdict::kOver);  // all in: idle_timeout alone
}

TEST(ReplayEndTest, MaxWallAndAClockThatNeverStarts) {
  ReplayEndOptions o;
  o.max_wall = 8.0;
  ReplayEnd end = Played(o);
  EXPECT_EQ(end.Check(8.5, 0), ReplayVerdict::kMaxWall);
  ReplayEndOptions waiting;
  ReplayEnd never(waiting, 0.0);
  for (double wall = 0.5; wall < 61.0; wall += 0.5) never.Clock(0.0, wall);  // ROS time 0: no /clock
  EXPECT_EQ(never.Check(59.0, 0), ReplayVerdict::kRunning);
  EXPECT_EQ(never.Check(60.5, 0), ReplayVerdict::kNoClock);
  // Wall time (no use_sim_time) never stands still: only max_wall ends such a report.
  ReplayEnd live(o, 0.0);
  for (double wall = 0.5; wall <= 7.5; wall += 0.5) live.Clock(1700000000.0 + wall, wall);
  EXPECT_EQ(live.Check(7.6, 0), ReplayVerdict::kRunning);
}

}  // namespace
}  // namespace clothwind::sensors
