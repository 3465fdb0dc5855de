#include "sensors/frame_resampler.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

// Pushes frames i = 0..n-1 stamped t0 + i / fps and returns, for every output tick, the index of the
// input frame it uses.
std::vector<int> PickedFrames(double fps, int n, double t0 = 1700000000.0) {
  FrameResampler r(25.0, 0.1);
  std::vector<int> picked;
  for (int i = 0; i < n; ++i) {
    const auto result = r.Push(t0 + i / fps);
    for (const auto& tick : result.ticks) {
      picked.push_back(tick.from_previous ? i - 1 : i);
      // The tick's source stamp is the picked frame's stamp.
      EXPECT_NEAR(tick.source_stamp, t0 + picked.back() / fps, 1e-6);
      EXPECT_NEAR(tick.stamp, t0 + tick.index / 25.0, 1e-6);
    }
  }
  return picked;
}

// Brute force: nearest input frame to each tick (ties to the earlier frame).
std::vector<int> NearestFrames(double fps, int n) {
  std::vector<int> picked;
  for (int k = 0; k / 25.0 <= (n - 1) / fps + 1e-9; ++k) {
    const double tau = k / 25.0;
    int best = 0;
    for (int i = 1; i < n; ++i)
      if (std::fabs(i / fps - tau) < std::fabs(best / fps - tau) - 1e-9) best = i;
    picked.push_back(best);
  }
  return picked;
}

TEST(FrameResamplerTest, SixtyToTwentyFivePicksNearestFrames) {
  const auto picked = PickedFrames(60.0, 121);  // 2 s
  ASSERT_EQ(picked.size(), 51u);                // ticks 0..50 at 0, 40 ms, ..., 2 s
  EXPECT_EQ(picked, NearestFrames(60.0, 121));
  // 12 input frames per 5 output ticks: 0, 2.4, 4.8, 7.2, 9.6 -> 0, 2, 5, 7, 10 (12 = frame at 0.2 s).
  const std::vector<int> first{0, 2, 5, 7, 10, 12};
  EXPECT_EQ(std::vector<int>(picked.begin(), picked.begin() + 6), first);
}

TEST(FrameResamplerTest, ThirtyToTwentyFivePicksNearestFrames) {
  const auto picked = PickedFrames(30.0, 61);
  ASSERT_EQ(picked.size(), 51u);
  EXPECT_EQ(picked, NearestFrames(30.0, 61));
  // Ticks at 0, 1.2, 2.4, 3.6, 4.8, 6 input periods -> 0, 1, 2, 4, 5, 6 (frame 3 is skipped).
  const std::vector<int> first{0, 1, 2, 4, 5, 6};
  EXPECT_EQ(std::vector<int>(picked.begin(), picked.begin() + 6), first);
}

TEST(FrameResamplerTest, UpsamplingRepeatsFrames) {
  // 20 fps -> 25 fps: some frames are used twice, all by nearest stamp.
  const auto picked = PickedFrames(20.0, 41);
  EXPECT_EQ(picked, NearestFrames(20.0, 41));
  EXPECT_EQ(picked.size(), 51u);
}

TEST(FrameResamplerTest, JitteredStampsStillPickNearest) {
  FrameResampler r(25.0, 0.1);
  const double t0 = 100.0;
  std::vector<double> stamps;
  for (int i = 0; i < 90; ++i) stamps.push_back(t0 + i / 30.0 + ((i * 7919) % 11 - 5) * 0.0005);
  std::vector<int64_t> indices;
  for (size_t i = 0; i < stamps.size(); ++i) {
    for (const auto& tick : r.Push(stamps[i]).ticks) {
      indices.push_back(tick.index);
      double best = stamps[0];
      for (size_t j = 0; j <= i; ++j)
        if (std::fabs(stamps[j] - tick.stamp) < std::fabs(best - tick.stamp)) best = stamps[j];
      EXPECT_DOUBLE_EQ(tick.source_stamp, best) << "tick " << tick.index;
    }
  }
  // Every tick of the ~2.97 s at 25 fps came, once each and in order (a resampler that emitted
  // none would pass the loop above).
  ASSERT_GE(indices.size(), 74u);
  ASSERT_LE(indices.size(), 75u);
  for (size_t k = 1; k < indices.size(); ++k) EXPECT_EQ(indices[k], indices[k - 1] + 1);
}

TEST(FrameResamplerTest, GapRestartsTheGrid) {
  FrameResampler r(25.0, 0.1);
  for (int i = 0; i < 10; ++i) EXPECT_FALSE(r.Push(i / 30.0).gap);
  // 0.09 s (two frames lost at 30 fps) is bridged; 0.2 s later is a gap.
  auto bridged = r.Push(9 / 30.0 + 0.09);
  EXPECT_FALSE(bridged.gap);
  EXPECT_EQ(bridged.ticks.size(), 2u);  // ticks at 0.32 and 0.36 s
  auto broken = r.Push(9 / 30.0 + 0.09 + 0.2);
  EXPECT_TRUE(broken.gap);
  EXPECT_TRUE(broken.restarted);
  ASSERT_EQ(broken.ticks.size(), 1u);
  EXPECT_EQ(broken.ticks[0].index, 0);  // new grid anchored at the frame after the gap
  EXPECT_DOUBLE_EQ(broken.ticks[0].stamp, 9 / 30.0 + 0.29);
}

TEST(FrameResamplerTest, DropsDuplicatesAndRestartsOnJumpBack) {
  FrameResampler r(25.0, 0.1);
  r.Push(10.0);
  r.Push(10.04);
  EXPECT_TRUE(r.Push(10.04).dropped);
  EXPECT_TRUE(r.Push(10.02).dropped);
  auto back = r.Push(5.0);  // bag restarted
  EXPECT_TRUE(back.restarted);
  EXPECT_TRUE(back.jumped_back);
  EXPECT_FALSE(back.gap);
  EXPECT_FALSE(back.dropped);
}

TEST(FrameResamplerTest, RejectsBadSettings) {
  EXPECT_THROW(FrameResampler(0.0, 0.1), std::invalid_argument);
  EXPECT_THROW(FrameResampler(25.0, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sensors
