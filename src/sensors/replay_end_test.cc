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

// rosbag play paused (space in its terminal): the clock stands still but its messages keep
// coming; the replay is over only once they stop (the player exited).
TEST(ReplayEndTest, APausedPlayerIsNotAnEndedOne) {
  ReplayEndOptions o;
  ReplayEnd end = Played(o);
  for (double wall = 10.0; wall <= 30.0; wall += 0.01) end.Player(wall);
  EXPECT_EQ(end.Check(30.0, 0), ReplayVerdict::kRunning);
  EXPECT_EQ(end.Check(34.9, 0), ReplayVerdict::kRunning);
  EXPECT_EQ(end.Check(35.1, 0), ReplayVerdict::kOver);
  // Before the clock starts, its messages (a player waiting for subscribers) are not a start.
  ReplayEnd waiting(o, 0.0);
  for (double wall = 0.0; wall <= 70.0; wall += 0.01) waiting.Player(wall);
  EXPECT_EQ(waiting.Check(70.0, 0), ReplayVerdict::kNoClock);
}

// sdn_node still working through its queue: a model taking 8 s a clip (slower than idle_timeout,
// whose backlog was cut off) is waited for, twice its pace after each estimate; a fast model's
// refused clip costs two of its (short) gaps; before two estimates, estimate_wait.
TEST(ReplayEndTest, ClipsWithoutTheirEstimateAreWaitedForAtTheModelsPace) {
  ReplayEndOptions o;
  o.estimate_wait = 30.0;
  ReplayEnd slow = Played(o);
  slow.Estimate(4.0);
  EXPECT_EQ(slow.Check(16.0, 3), ReplayVerdict::kRunning);  // one estimate: estimate_wait
  slow.Estimate(12.0);
  slow.Estimate(20.0);
  EXPECT_EQ(slow.Check(40.9, 2), ReplayVerdict::kRunning);  // 20 + 5 + 2 x 8
  EXPECT_EQ(slow.Check(41.1, 2), ReplayVerdict::kOver);     // the rest never came
  EXPECT_EQ(slow.Check(25.1, 0), ReplayVerdict::kOver);     // all in: idle_timeout alone
  ReplayEnd fast = Played(o);
  for (double wall = 2.0; wall <= 10.0; wall += 0.6) fast.Estimate(wall);
  EXPECT_EQ(fast.Check(16.4, 1), ReplayVerdict::kOver);     // 9.8 + 5 + 1.2: one clip refused
  ReplayEnd none = Played(o);
  EXPECT_EQ(none.Check(44.0, 1), ReplayVerdict::kRunning);  // the model still loading
  EXPECT_EQ(none.Check(45.1, 1), ReplayVerdict::kOver);     // 10 + 5 + 30
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
