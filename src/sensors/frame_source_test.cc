#include "sensors/frame_source.h"

#include <limits>

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

TEST(FramePacerTest, AWallClockStepMovesTheStamps) {
  FakeClock clock;
  FramePacer pacer(&clock, 10.0);
  int64_t stamp = 0;
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(pacer.WaitNext(1.0, &stamp));
  EXPECT_EQ(stamp, clock.RosNs());
  // NTP steps the wall clock back 100 s: the next stamps follow it, 100 ms apart as before
  // (they stayed 100 s ahead).
  clock.StepRos(-100000 * kMs);
  const int64_t before = stamp;
  ASSERT_TRUE(pacer.WaitNext(1.0, &stamp));
  EXPECT_EQ(stamp, clock.RosNs());
  EXPECT_EQ(stamp - before, -100000 * kMs + 100 * kMs);
  const int64_t after_step = stamp;
  ASSERT_TRUE(pacer.WaitNext(1.0, &stamp));
  EXPECT_EQ(stamp - after_step, 100 * kMs);
  // A wall clock that drifts by less than the 0.5 s threshold keeps the schedule's stamps.
  clock.StepRos(200 * kMs);
  const int64_t drifted = stamp;
  ASSERT_TRUE(pacer.WaitNext(1.0, &stamp));
  EXPECT_EQ(stamp - drifted, 100 * kMs);
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

// ROS time from /clock: 0 until Start (no /clock yet), then `rate` x the monotonic clock from
// `ros_ns`; Start again sets it back (a looped bag).
class SimulatedClock : public FakeClock {
 public:
  bool RosTimeIsSimulated() override { return true; }
  int64_t RosNs() override {
    if (!running_) return 0;
    return ros_at_start_ + static_cast<int64_t>(rate_ * static_cast<double>(MonotonicNs() - mono_at_start_));
  }
  void Start(int64_t ros_ns, double rate) {
    running_ = true;
    ros_at_start_ = ros_ns;
    mono_at_start_ = MonotonicNs();
    rate_ = rate;
  }

 private:
  bool running_ = false;
  int64_t ros_at_start_ = 0, mono_at_start_ = 0;
  double rate_ = 1.0;
};

TEST(FramePacerTest, UnderSimulatedTimeFramesWaitForTheClockAndFollowItsRate) {
  SimulatedClock clock;
  FramePacer pacer(&clock, 10.0);
  int64_t stamp = 0;
  // No /clock yet: no frame (they were stamped 0, in 1970, and every later one 1970 + k / rate).
  for (int i = 0; i < 5; ++i) EXPECT_FALSE(pacer.WaitNext(0.05, &stamp));
  const int64_t start = 1700000000LL * 1000000000LL;
  clock.Start(start, 0.5);  // rosbag play --clock -r 0.5
  ASSERT_TRUE(pacer.WaitNext(0.05, &stamp));
  EXPECT_EQ(stamp, start);
  // Each frame is stamped at its due instant in ROS time and released once ROS time reaches it,
  // so 20 frames take 4 s of wall time (2 s of ROS time at half speed). On the wall clock they
  // ran ahead of /clock by 0.5 s every second.
  const int64_t wall_start = clock.MonotonicNs();
  for (int k = 1; k <= 20; ++k) {
    while (!pacer.WaitNext(0.05, &stamp)) {
    }
    EXPECT_EQ(stamp, start + k * 100 * kMs);
    EXPECT_LE(stamp, clock.RosNs());
    EXPECT_GE(stamp, clock.RosNs() - kMs);
  }
  EXPECT_NEAR(static_cast<double>(clock.MonotonicNs() - wall_start), 4e9, 2e7);
  // The bag loops: ROS time goes back 2 s to exactly where the schedule started, and the schedule
  // restarts there at once. (It restarted only when time went back before the schedule's start;
  // back to the start itself, frame 21 stayed due 2.1 s later, which a looping bag never reaches:
  // the camera went silent after the first loop. This test waited those 2.1 s of fake time.)
  for (int loop = 0; loop < 2; ++loop) {
    clock.Start(start, 1.0);
    const int64_t looped_at = clock.MonotonicNs();
    while (!pacer.WaitNext(0.05, &stamp)) {
    }
    EXPECT_EQ(stamp, start) << "loop " << loop;
    EXPECT_LE(clock.MonotonicNs() - looped_at, 100 * kMs) << "loop " << loop;
    // And the rate goes on from there.
    while (!pacer.WaitNext(0.05, &stamp)) {
    }
    EXPECT_EQ(stamp, start + 100 * kMs) << "loop " << loop;
  }
}

// A bag played ten times faster (rosbag play -r 10): ROS time runs 10x the wall clock. The pacer
// slept a frame's interval of ROS time as wall time, woke 0.9 s of ROS time late at 10 fps, which
// passed the 0.5 s lag that restarts the schedule: every frame restarted it, and the stamps went
// out of step with the rate (and the clip buffer broke every clip at the holes).
TEST(FramePacerTest, UnderSimulatedTimeFasterThanTheWallClockTheScheduleHolds) {
  SimulatedClock clock;
  FramePacer pacer(&clock, 10.0);
  const int64_t start = 1700000000LL * 1000000000LL;
  clock.Start(start, 10.0);
  int64_t stamp = 0;
  for (int k = 0; k <= 50; ++k) {
    while (!pacer.WaitNext(0.1, &stamp)) {
    }
    EXPECT_EQ(stamp, start + k * 100 * kMs) << "frame " << k;
    EXPECT_LE(clock.RosNs() - stamp, 20 * kMs) << "frame " << k << " released late";
  }
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind

#include "sensors/frame_source_factory.h"

namespace clothwind {
namespace sensors {
namespace {

TEST(MakeFrameSourceTest, BuildsEachKindAndNamesBadOptions) {
  FakeClock clock;
  std::string error;
  FrameSourceOptions o;
  o.source = "v4l2";
  auto v4l2 = MakeFrameSource(o, &clock, {}, &error);
  ASSERT_NE(v4l2, nullptr) << error;
  EXPECT_EQ(v4l2->Status().at("device"), "/dev/video0");
  o.pixel_format = "NV12";
  EXPECT_EQ(MakeFrameSource(o, &clock, {}, &error), nullptr);
  EXPECT_NE(error.find("'NV12' is not one of YUYV, MJPEG, GREY"), std::string::npos) << error;
  o.pixel_format = "MJPEG";
  o.width = 0;
  EXPECT_EQ(MakeFrameSource(o, &clock, {}, &error), nullptr);
  EXPECT_NE(error.find("width and height"), std::string::npos) << error;
  // An unbounded timeout overflowed its nanoseconds: the camera was lost on every read.
  o.width = 640;
  for (double bad : {std::numeric_limits<double>::infinity(), 1e10}) {
    o.timeout_s = bad;
    EXPECT_EQ(MakeFrameSource(o, &clock, {}, &error), nullptr) << bad;
    EXPECT_NE(error.find("timeout must be > 0 and <= 86400 s"), std::string::npos) << error;
  }
  o.timeout_s = 2.0;
  o.fps = std::numeric_limits<double>::infinity();
  EXPECT_EQ(MakeFrameSource(o, &clock, {}, &error), nullptr);
  EXPECT_NE(error.find("<= 1000 Hz"), std::string::npos) << error;
  o.fps = 30;

  FrameSourceOptions f;
  f.source = "folder";
  EXPECT_EQ(MakeFrameSource(f, &clock, {}, &error), nullptr);
  EXPECT_NE(error.find("'folder' needs a path"), std::string::npos) << error;
  f.path = "/tmp";
  auto folder = MakeFrameSource(f, &clock, {}, &error);
  ASSERT_NE(folder, nullptr);
  EXPECT_EQ(folder->Status().at("source"), "folder");
  f.source = "video";
  EXPECT_EQ(MakeFrameSource(f, &clock, {}, &error)->Status().at("source"), "video");
  f.source = "rtsp";
  EXPECT_EQ(MakeFrameSource(f, &clock, {}, &error), nullptr);
  EXPECT_NE(error.find("'rtsp' is not one of v4l2, video, folder"), std::string::npos);
  f.source = "folder";
  f.fps = 0;
  EXPECT_EQ(MakeFrameSource(f, &clock, {}, &error), nullptr);
  EXPECT_NE(error.find("must be > 0 and <= 1000 Hz"), std::string::npos);
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
