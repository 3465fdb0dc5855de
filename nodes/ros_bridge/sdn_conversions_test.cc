#include "ros_bridge/sdn_conversions.h"

#include <limits>
#include <stdexcept>

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::ros_bridge {
namespace {

clothwind::Clip GreyClip(uint32_t frames = 30, uint32_t side = 8) {
  clothwind::Clip clip;
  clip.header.stamp = ros::Time(100.0);
  clip.header.frame_id = "camera_optical";
  clip.frame_rate = 25.0;
  clip.num_frames = frames;
  clip.width = clip.height = side;
  clip.encoding = "mono8";
  clip.data.assign(static_cast<size_t>(frames) * side * side, 7);
  return clip;
}

std::string Refusal(const clothwind::Clip& clip) {
  try {
    ClipFrames(clip);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ClipFramesTest, AGoodClipIsViewedFrameByFrame) {
  const clothwind::Clip clip = GreyClip();
  const std::vector<cv::Mat> frames = ClipFrames(clip);
  ASSERT_EQ(frames.size(), 30u);
  EXPECT_EQ(frames[29].data, clip.data.data() + 29 * 64);
  EXPECT_EQ(frames[0].size(), cv::Size(8, 8));
}

TEST(ClipFramesTest, SizesWhoseProductWrapsAreRefusedBeforeTheyAreMultiplied) {
  // 1923865 x 1718039348 x 5581 = 2^64 + 4: four bytes of data once passed the size check, and
  // reading the frames crashed the node.
  clothwind::Clip clip = GreyClip();
  clip.width = 1923865;
  clip.height = 1718039348;
  clip.num_frames = 5581;
  clip.data.assign(4, 1);
  EXPECT_NE(Refusal(clip).find("at most 16384 px"), std::string::npos) << Refusal(clip);
  clothwind::Clip many = GreyClip();
  many.num_frames = kMaxClipFrames + 1;
  EXPECT_NE(Refusal(many).find("num_frames at most 100000"), std::string::npos) << Refusal(many);
  clothwind::Clip edge = GreyClip(2, 1);  // the largest side passes this check (not the next: square)
  edge.width = kMaxClipSide;
  edge.data.assign(2 * kMaxClipSide, 7);
  EXPECT_EQ(Refusal(edge).find("at most 16384 px"), std::string::npos) << Refusal(edge);
}

TEST(ClipFramesTest, AClipMustBeASquareOfAtLeastEightPixels) {
  // A 2000 x 2 strip and a 1 x 1 clip were stretched to the network's square input and estimated
  // (6.4 m/s), diagnostics OK.
  clothwind::Clip strip = GreyClip(30, 2);
  strip.width = 2000;
  strip.data.assign(30 * 2000 * 2, 7);
  EXPECT_NE(Refusal(strip).find("must be equal (a square crop) and at least 8 px (got 2000 x 2)"), std::string::npos)
      << Refusal(strip);
  EXPECT_NE(Refusal(GreyClip(30, 1)).find("(got 1 x 1)"), std::string::npos) << Refusal(GreyClip(30, 1));
  EXPECT_NE(Refusal(GreyClip(30, 7)).find("(got 7 x 7)"), std::string::npos) << Refusal(GreyClip(30, 7));
  EXPECT_EQ(Refusal(GreyClip(30, 8)), "accepted");
}

TEST(ClipFramesTest, AClipStampedZeroIsRefused) {
  clothwind::Clip clip = GreyClip();
  clip.header.stamp = ros::Time();
  EXPECT_NE(Refusal(clip).find("Clip.header.stamp is 0"), std::string::npos) << Refusal(clip);
  // With frame stamps, the first frame's is the clip's.
  clip.header.stamp = ros::Time(100.0);
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps.push_back(ros::Time(i * 0.04));
  EXPECT_NE(Refusal(clip).find("Clip.frame_stamps[0] is 0"), std::string::npos) << Refusal(clip);
  for (auto& s : clip.frame_stamps) s += ros::Duration(50.0);
  EXPECT_EQ(Refusal(clip), "accepted");
}

TEST(ClipFramesTest, AClipWhoseFramesWouldEndBeyondRosTimeIsMalformed) {
  // No frame stamps, a header stamp near TIME_MAX: its last frame's stamp is beyond 32-bit
  // seconds. ros::Time's operator threw a runtime_error (counted as the model's failure).
  clothwind::Clip clip = GreyClip();
  clip.frame_stamps.clear();
  clip.header.stamp = ros::Time(4294967295, 0);
  EXPECT_THROW(ClipEnd(clip), std::invalid_argument);
  EXPECT_THROW(ClipFrameStamp(clip, clip.num_frames - 1), std::invalid_argument);
  clip.header.stamp = ros::Time(100, 0);
  EXPECT_NEAR(ClipEnd(clip).toSec(), 100.0 + (clip.num_frames - 1) / clip.frame_rate, 1e-6);
}

std::string RateRefusal(const clothwind::Clip& clip, double model_rate) {
  try {
    CheckClipFrameRate(clip, model_rate);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(CheckClipFrameRateTest, TheRateMustBeTheModelsAndTheStampsMustAgreeWithIt) {
  clothwind::Clip clip = GreyClip();
  EXPECT_EQ(RateRefusal(clip, 25.0), "accepted");
  EXPECT_NE(RateRefusal(clip, 30.0).find("Clip.frame_rate is 25"), std::string::npos) << RateRefusal(clip, 30.0);
  clip.frame_rate = std::numeric_limits<float>::quiet_NaN();
  EXPECT_NE(RateRefusal(clip, 25.0).find("Clip.frame_rate"), std::string::npos);
  clip.frame_rate = 25.0;
  // Stamps 1/25 s apart, as clip_buffer resamples them (nanosecond rounding included): accepted.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps.push_back(ros::Time(100.0 + i / 25.0));
  EXPECT_EQ(RateRefusal(clip, 25.0), "accepted");
  // Stamps 1/50 s apart under a 25 Hz rate: every frequency would be read at half its value.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps[i] = ros::Time(100.0 + i / 50.0);
  EXPECT_NE(RateRefusal(clip, 25.0).find("Clip.frame_stamps[1] is 0.02"), std::string::npos)
      << RateRefusal(clip, 25.0);
  // One hole of a frame in otherwise good stamps.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps[i] = ros::Time(100.0 + (i + (i >= 12)) / 25.0);
  EXPECT_NE(RateRefusal(clip, 25.0).find("Clip.frame_stamps[12]"), std::string::npos) << RateRefusal(clip, 25.0);
  // Stamps 1/27 s apart: each gap within 10 % of 1/25 s, the clip 7 % short.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps[i] = ros::Time(100.0 + i / 27.0);
  EXPECT_NE(RateRefusal(clip, 25.0).find("Clip.frame_stamps span"), std::string::npos) << RateRefusal(clip, 25.0);
  // A camera's jitter of 2 ms about exact stamps: accepted.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps[i] = ros::Time(100.0 + i / 25.0 + (i % 2) * 0.002);
  EXPECT_EQ(RateRefusal(clip, 25.0), "accepted");
  // Stamps more than 2^31 s apart (increasing, so not refused before): ros::Time's difference threw
  // a runtime_error, which sdn_node reported as the model failing on the clip.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps[i] = ros::Time(i == 0 ? 1.0 : 3e9 + i);
  EXPECT_NE(RateRefusal(clip, 25.0).find("Clip.frame_stamps[1]"), std::string::npos) << RateRefusal(clip, 25.0);
}

TEST(ToWindEstimateTest, TheEstimateSpansTheFramesTheModelRead) {
  learn::Prediction p;
  p.speed = 3.0;
  p.speed_std = 0.5;
  clothwind::Clip clip = GreyClip(40);
  // Without frame stamps: the last 30 of 40 frames at 25 fps start 10 periods after the first.
  clip.sequence = 17;
  clothwind::WindEstimate e = ToWindEstimate(clip, p, 0.01, "m", 30);
  // What it carries over: each field its own source (the window's stamps aside, only the rostests
  // saw these, and a std copied from the speed passed here).
  EXPECT_EQ(e.speed, 3.0);
  EXPECT_EQ(e.speed_std, 0.5);
  EXPECT_EQ(e.latency, 0.01);
  EXPECT_EQ(e.model, "m");
  EXPECT_EQ(e.clip_sequence, 17u);
  EXPECT_EQ(e.header.frame_id, "camera_optical");
  EXPECT_TRUE(std::isnan(e.reference_speed));  // no anemometer reading in the clip's window
  clip.wind_count = 2;
  clip.wind_mean = 4.2;
  EXPECT_EQ(ToWindEstimate(clip, p, 0.01, "m", 30).reference_speed, 4.2);
  clip.wind_count = 0;
  EXPECT_NEAR((e.clip_start - clip.header.stamp).toSec(), 0.4, 1e-6);
  EXPECT_NEAR((e.clip_end - clip.header.stamp).toSec(), 39 * 0.04, 1e-6);
  EXPECT_EQ(e.header.stamp, e.clip_end);
  EXPECT_EQ(ToWindEstimate(clip, p, 0.01, "m", 0).clip_start, clip.header.stamp);   // all frames
  EXPECT_EQ(ToWindEstimate(clip, p, 0.01, "m", 50).clip_start, clip.header.stamp);  // fewer than read
  // With frame stamps, the first frame read's own.
  for (uint32_t i = 0; i < clip.num_frames; ++i) clip.frame_stamps.push_back(ros::Time(200.0 + i * 0.05));
  e = ToWindEstimate(clip, p, 0.01, "m", 30);
  EXPECT_EQ(e.clip_start, clip.frame_stamps[10]);
  EXPECT_EQ(e.clip_end, clip.frame_stamps[39]);
}

}  // namespace
}  // namespace clothwind::ros_bridge
