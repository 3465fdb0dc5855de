#include "sensors/frame_timestamp.h"

#include <random>

#include <gtest/gtest.h>

#include "sensors/frame_timestamp_fake_clock.h"

namespace clothwind {
namespace sensors {
namespace {

constexpr int64_t kMs = 1000000;

TEST(ClockOffsetEstimatorTest, TakesTheMinimumOverTheWindowOnly) {
  ClockOffsetEstimator e(3);
  EXPECT_FALSE(e.HasEstimate());
  e.AddSample(0, 50);  // offset 50
  e.AddSample(0, 10);  // 10
  e.AddSample(0, 30);  // 30
  EXPECT_EQ(e.OffsetNs(), 10);
  e.AddSample(0, 40);  // window {10, 30, 40}
  EXPECT_EQ(e.OffsetNs(), 10);
  e.AddSample(0, 35);  // window {30, 40, 35}: the 10 slid out
  EXPECT_EQ(e.OffsetNs(), 30);
  e.AddSample(0, -5);  // a backward step of the ROS clock is followed at once
  EXPECT_EQ(e.OffsetNs(), -5);
  e.Reset();
  EXPECT_FALSE(e.HasEstimate());
  EXPECT_EQ(e.OffsetNs(), 0);
}

TEST(ClockOffsetEstimatorTest, MatchesBruteForceSlidingMinimum) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int64_t> d(-1000, 1000);
  const int window = 7;
  ClockOffsetEstimator e(window);
  std::vector<int64_t> offsets;
  for (int i = 0; i < 200; ++i) {
    const int64_t off = d(rng);
    offsets.push_back(off);
    e.AddSample(1000 + i, 1000 + i + off);
    int64_t expected = offsets.back();
    for (int k = std::max(0, i - window + 1); k <= i; ++k) expected = std::min(expected, offsets[k]);
    ASSERT_EQ(e.OffsetNs(), expected) << "sample " << i;
  }
}

// The failure to avoid (usb_cam #75/#385): stamping frames with the time they were dequeued or
// published. Frames are captured every 33 ms but dequeued after a varying latency, and the
// thread is sometimes preempted between the two clock reads; the stamps must still be the
// capture instants in ROS time.
TEST(FrameTimestamperTest, MonotonicDriverStampsFollowCaptureNotDequeueTime) {
  FakeClock clock;
  FrameTimestamper stamper(&clock, 30);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int64_t> latency_ms(2, 40);
  int64_t capture = clock.MonotonicNs() + 5 * kMs;
  for (int i = 0; i < 100; ++i, capture += 33 * kMs) {
    const int64_t dequeue = capture + latency_ms(rng) * kMs;
    clock.Advance(dequeue - clock.MonotonicNs());
    // Preempted between the two reads: read in the other order (ROS time first), this delay
    // would shrink the offset the minimum keeps, and every later stamp would come 15 ms early.
    if (i % 4 == 1) clock.DelayAfterNextRead(15 * kMs);
    const int64_t stamp = stamper.Map(capture, DriverClock::kMonotonic);
    const int64_t truth = capture + clock.ros_offset_ns();
    if (i == 1) {
      // Only delayed samples so far besides the first: still the first (clean) one's offset.
      EXPECT_EQ(stamp, truth);
    }
    EXPECT_EQ(stamp, truth) << "frame " << i;
    // And clearly not the dequeue time.
    EXPECT_LT(stamp, clock.RosNs() - kMs);
  }
}

TEST(FrameTimestamperTest, UnknownDriverClockUsesMinimumLatency) {
  FakeClock clock;
  FrameTimestamper stamper(&clock, 50);
  const int64_t driver_epoch = 5000 * kMs;  // the driver's clock is unrelated to ours
  std::mt19937 rng(5);
  std::uniform_int_distribution<int64_t> latency_ms(8, 30);
  int64_t min_latency = INT64_MAX;
  const int64_t base = clock.MonotonicNs() + 40 * kMs;
  for (int i = 0; i < 50; ++i) {
    const int64_t capture_mono = base + i * 40 * kMs;
    const int64_t latency = latency_ms(rng) * kMs;
    min_latency = std::min(min_latency, latency);
    clock.Advance(capture_mono + latency - clock.MonotonicNs());
    stamper.Map(driver_epoch + i * 40 * kMs, DriverClock::kUnknown);
  }
  // After the window has seen the smallest latency, a frame maps to capture + min latency,
  // whatever its own latency.
  const int64_t capture_mono = base + 50 * 40 * kMs;
  clock.Advance(capture_mono + 29 * kMs - clock.MonotonicNs());
  const int64_t stamp = stamper.Map(driver_epoch + 50 * 40 * kMs, DriverClock::kUnknown);
  EXPECT_EQ(stamp, capture_mono + clock.ros_offset_ns() + min_latency);
}

TEST(FrameTimestamperTest, ZeroStampFallsBackToNowAndClockChangeResets) {
  FakeClock clock;
  FrameTimestamper stamper(&clock);
  EXPECT_EQ(stamper.Map(0, DriverClock::kMonotonic), clock.RosNs());
  // An unknown-clock offset must not leak into monotonic mapping. The unknown clock runs 1 s
  // ahead of the monotonic one, so its offset (ROS - driver) is 1 s smaller than the monotonic
  // offset: were the estimator not reset on the change of clock, that leaked sample would be
  // the window's minimum and shift the monotonic stamps 1 s early.
  stamper.Map(clock.MonotonicNs() + 1000 * kMs, DriverClock::kUnknown);
  EXPECT_EQ(stamper.OffsetNs(), clock.ros_offset_ns() - 1000 * kMs);
  clock.Advance(5 * kMs);
  const int64_t capture = clock.MonotonicNs() - 10 * kMs;
  EXPECT_EQ(stamper.Map(capture, DriverClock::kMonotonic), capture + clock.ros_offset_ns());
  EXPECT_EQ(stamper.OffsetNs(), clock.ros_offset_ns());
  // And back to an unknown clock, now 1 s behind: its offset is 1 s larger than the monotonic
  // one, which would win the minimum were the monotonic samples kept; alone, the frame maps to
  // the time it was dequeued.
  clock.Advance(5 * kMs);
  const int64_t behind = clock.MonotonicNs() - 1000 * kMs;
  EXPECT_EQ(stamper.Map(behind, DriverClock::kUnknown), clock.RosNs());
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
