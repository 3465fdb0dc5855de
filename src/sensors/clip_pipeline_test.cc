#include "sensors/clip_pipeline.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

constexpr double kT0 = 1700000000.0;

// A 64x48 mono frame whose every pixel is the frame number (mod 256), so the output shows which
// camera frame each clip frame came from.
cv::Mat Numbered(int i) { return cv::Mat(48, 64, CV_8UC1, cv::Scalar(i % 256)); }

ClipPipelineOptions SmallOptions() {
  ClipPipelineOptions o;
  o.num_frames = 10;
  o.stride = 10;
  o.size = 16;
  o.label_window = 5.0;
  o.label_delay = 1.5;
  return o;
}

TEST(ClipPipelineTest, SixtyFpsStreamBecomesTwentyFiveFpsClips) {
  ClipPipeline p(SmallOptions());
  for (int i = 0; i < 60 * 3; ++i) p.AddFrame(kT0 + i / 60.0, Numbered(i), ClipSourceEncoding::kMono8);
  const auto clips = p.Flush();
  // 3 s at 60 fps: ticks 0..74 (last frame at 2.983 s) -> 7 clips of 10.
  ASSERT_EQ(clips.size(), 7u);
  for (size_t c = 0; c < clips.size(); ++c) {
    const auto& frames = clips[c].clip.frames;
    ASSERT_EQ(frames.size(), 10u);
    EXPECT_EQ(clips[c].clip.sequence, c);
    EXPECT_EQ(clips[c].roi.size, 48);
    EXPECT_EQ(clips[c].roi.x, 8);
    for (size_t f = 0; f < frames.size(); ++f) {
      const int tick = static_cast<int>(c * 10 + f);
      EXPECT_NEAR(frames[f].stamp, kT0 + tick / 25.0, 1e-6);
      const int nearest = static_cast<int>(std::lround(tick * 60.0 / 25.0 - 1e-9));
      EXPECT_EQ(frames[f].image.at<uint8_t>(8, 8), nearest % 256) << "tick " << tick;
      EXPECT_EQ(frames[f].image.rows, 16);
    }
  }
  EXPECT_EQ(p.stats().frames_in, 180u);
  EXPECT_EQ(p.stats().frames_out, 75u);
  EXPECT_EQ(p.stats().clips_made, 7u);
}

TEST(ClipPipelineTest, GapBreaksTheClip) {
  ClipPipeline p(SmallOptions());
  int i = 0;
  for (; i < 30; ++i) p.AddFrame(kT0 + i / 30.0, Numbered(i), ClipSourceEncoding::kMono8);
  // 0.5 s of frames lost, then 1 s more.
  for (int j = 0; j < 30; ++j) p.AddFrame(kT0 + (i + 15 + j) / 30.0, Numbered(i + 15 + j), ClipSourceEncoding::kMono8);
  const auto clips = p.Flush();
  EXPECT_EQ(p.stats().gaps, 1u);
  EXPECT_NEAR(p.stats().last_gap, 16 / 30.0, 1e-6);  // frame 29 to frame 45
  for (const auto& c : clips) {
    const auto& f = c.clip.frames;
    // No clip spans the hole: its frames are exactly 40 ms apart.
    EXPECT_NEAR(f.back().stamp - f.front().stamp, 9 / 25.0, 1e-6);
    EXPECT_TRUE(f.back().stamp < kT0 + 1.0 || f.front().stamp > kT0 + 1.4);
  }
  // 25 ticks before (2 clips) and 25 after (2 clips): the partial clips are dropped.
  EXPECT_EQ(clips.size(), 4u);
}

TEST(ClipPipelineTest, LabelWaitsForLateReadingsByStamp) {
  ClipPipelineOptions o = SmallOptions();
  ClipPipeline p(o);
  // Readings at 1 Hz with speed 2, except the one stamped at 6 s (speed 8) which arrives late.
  for (int s = 0; s <= 5; ++s) p.AddReading({kT0 + s, 2.0, 0.0});
  for (int i = 0; i <= 6 * 30; ++i) p.AddFrame(kT0 + i / 30.0, Numbered(i), ClipSourceEncoding::kMono8);
  // Clips end at ticks 9, 19, ..., 149 (5.96 s); data time is 6 s, so only clips ending by
  // 6 - label_delay = 4.5 s are due.
  auto ready = p.TakeReady();
  for (const auto& c : ready) EXPECT_LE(c.clip.frames.back().stamp, kT0 + 4.5 + 1e-6);
  EXPECT_EQ(ready.size(), 11u);  // ticks 9 .. 109 (4.36 s)
  EXPECT_EQ(ready.back().label.count, 5u);  // readings 0..4 in [kT0 - 0.64, kT0 + 4.36]
  p.AddReading({kT0 + 5.5, 8.0, 0.0});  // late, but stamped before the next clips' ends
  for (int i = 181; i <= 9 * 30; ++i) p.AddFrame(kT0 + i / 30.0, Numbered(i), ClipSourceEncoding::kMono8);
  ready = p.TakeReady();
  ASSERT_FALSE(ready.empty());
  const auto& last = ready.back();  // the clip ending at 7.16 s: window [2.16, 7.16]
  EXPECT_NEAR(last.clip.frames.back().stamp, kT0 + 7.16, 1e-6);
  EXPECT_EQ(last.label.count, 4u);  // readings at 3, 4, 5 and the late 5.5
  EXPECT_DOUBLE_EQ(last.label.mean, (2.0 * 3 + 8.0) / 4);
  EXPECT_NEAR(last.label.std, std::sqrt((3 * 1.5 * 1.5 + 4.5 * 4.5) / 4), 1e-12);
  EXPECT_EQ(p.stats().readings_late, 0u);
  // A reading stamped inside an already released window is counted as late.
  p.AddReading({kT0 + 1.0, 1.0, 0.0});
  EXPECT_EQ(p.stats().readings_late, 1u);
}

TEST(ClipPipelineTest, TimeJumpingBackStartsOver) {
  // A bag played twice (rosbag play -l): the second pass must not mix with the first.
  ClipPipeline p(SmallOptions());
  for (int s = 0; s <= 3; ++s) p.AddReading({kT0 + s, 9.0, 0.0});
  for (int i = 0; i < 90; ++i) p.AddFrame(kT0 + i / 30.0, Numbered(i), ClipSourceEncoding::kMono8);
  EXPECT_GT(p.pending(), 0u);
  // Back to the start: waiting clips and first-pass readings are dropped.
  for (int i = 0; i < 20; ++i) p.AddFrame(kT0 + i / 30.0, Numbered(i), ClipSourceEncoding::kMono8);
  p.AddReading({kT0 + 0.2, 1.0, 0.0});
  const auto clips = p.Flush();
  ASSERT_EQ(clips.size(), 1u);  // ticks 0..15 of the second pass: one clip of 10
  EXPECT_NEAR(clips[0].clip.frames.front().stamp, kT0, 1e-6);
  EXPECT_EQ(clips[0].label.count, 1u);
  EXPECT_DOUBLE_EQ(clips[0].label.mean, 1.0);
}

TEST(ClipPipelineTest, BgrFramesAreCroppedToRoi) {
  ClipPipelineOptions o = SmallOptions();
  o.roi = {0, 0, 20};
  ClipPipeline p(o);
  for (int i = 0; i < 15; ++i) {
    cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(0, 0, 0));
    bgr(cv::Rect(0, 0, 20, 20)).setTo(cv::Scalar(255, 255, 255));
    p.AddFrame(kT0 + i / 30.0, bgr, ClipSourceEncoding::kBgr8);
  }
  const auto clips = p.Flush();
  ASSERT_EQ(clips.size(), 1u);
  EXPECT_EQ(clips[0].clip.frames[0].image.at<uint8_t>(8, 8), 255);  // only the white square
  cv::Mat too_small(10, 10, CV_8UC3);
  EXPECT_THROW(p.AddFrame(kT0 + 1.0, too_small, ClipSourceEncoding::kBgr8), std::invalid_argument);
  EXPECT_EQ(p.stats().frames_dropped, 1u);
}

TEST(ClipPipelineTest, ColourOptionMakesBgrClips) {
  ClipPipelineOptions o = SmallOptions();
  o.colour = true;
  ClipPipeline p(o);
  for (int i = 0; i < 15; ++i) {
    cv::Mat bgr(48, 64, CV_8UC3, cv::Scalar(10, 20, i));
    p.AddFrame(kT0 + i / 30.0, bgr, ClipSourceEncoding::kBgr8);
  }
  const auto clips = p.Flush();
  ASSERT_EQ(clips.size(), 1u);
  for (const auto& f : clips[0].clip.frames) {
    ASSERT_EQ(f.image.type(), CV_8UC3);
    ASSERT_EQ(f.image.rows, o.size);
    // Blue and green as sent; red says which camera frame this tick showed (nearest by stamp).
    const cv::Vec3b px = f.image.at<cv::Vec3b>(3, 3);
    EXPECT_EQ(px[0], 10);
    EXPECT_EQ(px[1], 20);
    EXPECT_NEAR(f.source_stamp, kT0 + px[2] / 30.0, 1e-9);
  }
}

}  // namespace
}  // namespace clothwind::sensors
