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
  EXPECT_NE(error.find("must be > 0 Hz"), std::string::npos);
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
