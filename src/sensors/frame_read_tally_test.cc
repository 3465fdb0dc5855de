#include "sensors/frame_read_tally.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sensors/frame_timestamp_fake_clock.h"
#include "sensors/v4l2_camera.h"
#include "sensors/v4l2_fake_device.h"

namespace clothwind::sensors {
namespace {

V4l2Options Grey15() {
  V4l2Options o;
  o.device = "/dev/video7";
  o.format = PixelFormat::kGrey;
  o.width = 320;
  o.height = 240;
  o.fps = 15;
  o.backoff_initial_s = 0.25;
  o.backoff_max_s = 1.0;
  return o;
}

// Reads a camera for `seconds` of its clock, tallying every outcome as camera_node does.
void ReadFor(V4l2Camera* camera, FakeClock* clock, double seconds, FrameReadTally* tally) {
  const int64_t end = clock->MonotonicNs() + static_cast<int64_t>(seconds * 1e9);
  Frame f;
  while (clock->MonotonicNs() < end) tally->Record(camera->Read(&f, 0.1), camera->error());
}

// An unplugged camera is one failure per failed reopen, and not a single unreadable frame: the
// node's one "read errors" count reported 8 s unplugged as "10 frames unreadable" (the loss, then 9 failed reopens).
TEST(FrameReadTallyTest, AnUnpluggedCameraFailsButReadsNoBadFrame) {
  FakeClock clock;
  FakeV4l2Device device(&clock, {});
  V4l2Camera camera(Grey15(), &device, &clock);
  ASSERT_TRUE(camera.Open());
  FrameReadTally tally;
  ReadFor(&camera, &clock, 1.0, &tally);
  EXPECT_GE(tally.frames(), 14u);
  EXPECT_TRUE(tally.TakeReport().empty());

  device.Unplug();
  ReadFor(&camera, &clock, 8.0, &tally);
  EXPECT_EQ(tally.bad_frames(), 0u);
  // The loss, then one failed reopen per backoff step (0.25, 0.5, 1, 1, ... s).
  EXPECT_EQ(tally.failures(), camera.stats().losses + camera.stats().open_failures);
  EXPECT_GE(tally.failures(), 8u);
  const std::vector<std::string> report = tally.TakeReport();
  ASSERT_EQ(report.size(), 1u);
  EXPECT_NE(report[0].find(std::to_string(tally.failures()) + " source failures"), std::string::npos) << report[0];
  EXPECT_NE(report[0].find("/dev/video7: cannot open"), std::string::npos) << report[0];

  device.Replug();
  const uint64_t frames_before = tally.frames();
  ReadFor(&camera, &clock, 2.0, &tally);
  EXPECT_GT(tally.frames(), frames_before);
  EXPECT_TRUE(tally.TakeReport().empty());  // a new report: nothing new went wrong
}

// A camera that sends corrupt buffers keeps streaming: bad frames, no failure, until no good frame
// has come for the loss timeout.
TEST(FrameReadTallyTest, CorruptBuffersAreBadFramesNotFailures) {
  FakeClock clock;
  FakeV4l2Config config;
  config.error_from = 5;
  FakeV4l2Device device(&clock, config);
  V4l2Options options = Grey15();
  options.timeout_s = 2.0;
  V4l2Camera camera(options, &device, &clock);
  ASSERT_TRUE(camera.Open());
  FrameReadTally tally;
  ReadFor(&camera, &clock, 1.5, &tally);
  EXPECT_EQ(tally.frames(), 5u);
  EXPECT_EQ(tally.failures(), 0u);
  EXPECT_EQ(tally.bad_frames(), camera.stats().corrupt);
  EXPECT_GE(tally.bad_frames(), 10u);
  const std::vector<std::string> report = tally.TakeReport();
  ASSERT_EQ(report.size(), 1u);
  EXPECT_EQ(report[0].rfind(std::to_string(tally.bad_frames()) + " frames unreadable since last report: ", 0), 0u)
      << report[0];
  EXPECT_NE(report[0].find("corrupt"), std::string::npos) << report[0];
}

TEST(FrameReadTallyTest, ReportsCountOnlyWhatIsNew) {
  FrameReadTally tally;
  tally.Record(ReadStatus::kNoFrame, "");
  tally.Record(ReadStatus::kEnd, "");
  EXPECT_TRUE(tally.TakeReport().empty());
  tally.Record(ReadStatus::kBadFrame, "a");
  tally.BadFrame("b");  // a message that could not be built
  tally.Record(ReadStatus::kError, "lost");
  tally.SourceFailed("gone");  // an Open that failed
  std::vector<std::string> report = tally.TakeReport();
  ASSERT_EQ(report.size(), 2u);
  EXPECT_EQ(report[0], "2 frames unreadable since last report: b");
  EXPECT_EQ(report[1].rfind("2 source failures (", 0), 0u) << report[1];
  EXPECT_NE(report[1].find(": gone"), std::string::npos);
  tally.Record(ReadStatus::kBadFrame, "c");
  report = tally.TakeReport();
  ASSERT_EQ(report.size(), 1u);
  EXPECT_EQ(report[0], "1 frame unreadable since last report: c");
  EXPECT_EQ(tally.bad_frames(), 3u);
  EXPECT_EQ(tally.failures(), 2u);
  EXPECT_EQ(tally.last_failure(), "gone");
}

}  // namespace
}  // namespace clothwind::sensors
