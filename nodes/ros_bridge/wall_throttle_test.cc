#include "ros_bridge/wall_throttle.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

namespace clothwind::ros_bridge {
namespace {

TEST(WallThrottle, FirstCallThenOncePerPeriodAndAgainAfterAStepBack) {
  WallThrottle t;
  EXPECT_TRUE(t.DueAt(1000.0, 5.0));  // the first, whatever the time (ROS's needed now >= period)
  EXPECT_FALSE(t.DueAt(1001.0, 5.0));
  EXPECT_FALSE(t.DueAt(1004.9, 5.0));
  EXPECT_TRUE(t.DueAt(1005.0, 5.0));
  EXPECT_TRUE(t.DueAt(990.0, 5.0));  // the clock stepped back: not silenced for 15 s
  EXPECT_FALSE(t.DueAt(991.0, 5.0));
}

TEST(WallThrottle, TheFirstMessageComesAtRosTimeZero) {
  // Under use_sim_time before /clock, ROS time is 0: ROS_*_THROTTLE's check (0 + period <= 0)
  // never passed. The wall throttle does not read ROS time at all.
  ros::Time::init();
  ros::Time::setNow(ros::Time(0, 0));
  WallThrottle t;
  EXPECT_TRUE(t.Due(5.0));
  EXPECT_FALSE(t.Due(5.0));
  // And the period is counted in wall time while ROS time stands still at 0: a throttle that
  // read ROS time (stuck at 0, never a period past its first message) would stay silent after it.
  WallThrottle fast;
  EXPECT_TRUE(fast.Due(0.05));
  std::this_thread::sleep_for(std::chrono::milliseconds(60));
  EXPECT_EQ(ros::Time::now(), ros::Time(0, 0));
  EXPECT_TRUE(fast.Due(0.05));  // 60 ms of wall time > the 50 ms period
}

}  // namespace
}  // namespace clothwind::ros_bridge
