#include "sensors/frame_source.h"

#include <gtest/gtest.h>

#include "sensors/frame_timestamp_fake_clock.h"

namespace clothwind {
namespace sensors {
namespace {

constexpr int64_t kMs = 1000000;

TEST(FramePacerTest, StampsAreTheDueInstantsAtTheRate) {
  FakeClock clock;
  FramePacer pacer(&clock, 20.0);
  const int64_t start_ros = clock.RosNs();
  int64_t stamp = 0;
  ASSERT_TRUE(pacer.WaitNext(1.0, &stamp));  // first frame: due at once
  EXPECT_EQ(stamp, start_ros);
  for (int k = 1; k < 10; ++k) {
    clock.Advance(7 * kMs);  // some work between frames; the pacer sleeps the rest
    ASSERT_TRUE(pacer.WaitNext(1.0, &stamp));
    EXPECT_EQ(stamp, start_ros + k * 50 * kMs);
    EXPECT_EQ(clock.RosNs(), stamp);  // released exactly when due
  }
}

TEST(FramePacerTest, ShortWaitReturnsFalseWithoutSkipping) {
  FakeClock clock;
  FramePacer pacer(&clock, 10.0);
  int64_t stamp = 0;
  ASSERT_TRUE(pacer.WaitNext(0.0, &stamp));
  const int64_t first = stamp;
  EXPECT_FALSE(pacer.WaitNext(0.03, &stamp));  // due in 100 ms
  EXPECT_FALSE(pacer.WaitNext(0.03, &stamp));
  EXPECT_FALSE(pacer.WaitNext(0.03, &stamp));
  ASSERT_TRUE(pacer.WaitNext(0.03, &stamp));
  EXPECT_EQ(stamp, first + 100 * kMs);
}

TEST(FramePacerTest, LateReadsKeepTheScheduleButLongStallsRestartIt) {
  FakeClock clock;
  FramePacer pacer(&clock, 10.0);
  int64_t stamp = 0;
  ASSERT_TRUE(pacer.WaitNext(0, &stamp));
  const int64_t first = stamp;
  clock.Advance(130 * kMs);  // 30 ms late for frame 1: it keeps its slot
  ASSERT_TRUE(pacer.WaitNext(0, &stamp));
  EXPECT_EQ(stamp, first + 100 * kMs);
  clock.Advance(2000 * kMs);  // a long stall: no burst of stale frames, restart from now
  ASSERT_TRUE(pacer.WaitNext(0, &stamp));
  EXPECT_EQ(stamp, clock.RosNs());
  ASSERT_FALSE(pacer.WaitNext(0, &stamp));
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
