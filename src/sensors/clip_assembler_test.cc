#include "sensors/clip_assembler.h"

#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

ClipFrame Frame(int64_t tick) { return {tick, tick / 25.0, tick / 25.0, cv::Mat()}; }

// Feeds ticks [from, to) and returns the first tick of every clip made.
std::vector<int64_t> Starts(ClipAssembler& a, int64_t from, int64_t to) {
  std::vector<int64_t> starts;
  for (int64_t t = from; t < to; ++t) {
    if (auto clip = a.Add(Frame(t))) {
      EXPECT_EQ(static_cast<int>(clip->frames.size()), a.num_frames());
      for (size_t i = 1; i < clip->frames.size(); ++i)
        EXPECT_EQ(clip->frames[i].tick, clip->frames[i - 1].tick + 1);
      EXPECT_EQ(clip->frames.back().tick, t);
      starts.push_back(clip->frames.front().tick);
    }
  }
  return starts;
}

TEST(ClipAssemblerTest, BackToBackClips) {
  ClipAssembler a(30, 30);
  EXPECT_EQ(Starts(a, 0, 100), (std::vector<int64_t>{0, 30, 60}));
  EXPECT_EQ(a.clips_made(), 3u);
}

TEST(ClipAssemblerTest, OverlappingAndSkippingStrides) {
  ClipAssembler overlap(30, 10);
  EXPECT_EQ(Starts(overlap, 0, 60), (std::vector<int64_t>{0, 10, 20, 30}));
  ClipAssembler skip(30, 45);
  EXPECT_EQ(Starts(skip, 0, 130), (std::vector<int64_t>{0, 45, 90}));
}

TEST(ClipAssemblerTest, SequenceNumbersRun) {
  ClipAssembler a(2, 2);
  std::vector<uint64_t> seq;
  for (int t = 0; t < 6; ++t)
    if (auto c = a.Add(Frame(t))) seq.push_back(c->sequence);
  EXPECT_EQ(seq, (std::vector<uint64_t>{0, 1, 2}));
}

TEST(ClipAssemblerTest, BreakDiscardsPartialClip) {
  ClipAssembler a(30, 30);
  EXPECT_EQ(Starts(a, 0, 50), (std::vector<int64_t>{0}));
  a.Break();  // 20 frames of the second clip lost
  EXPECT_EQ(a.breaks(), 1u);
  EXPECT_EQ(a.frames_discarded(), 20u);
  // The new stream's ticks restart at 0: the first clip is 30 frames after the break.
  EXPECT_EQ(Starts(a, 0, 40), (std::vector<int64_t>{0}));
}

TEST(ClipAssemblerTest, BreakWithAWideStrideDiscardsOnlyTheNextClipsFrames) {
  ClipAssembler a(30, 150);  // clips end at frames 30, 180, 330, ...: the next one holds 151-180
  EXPECT_EQ(Starts(a, 0, 100), (std::vector<int64_t>{0}));
  a.Break();  // frames 31-100 belong to no clip
  EXPECT_EQ(a.frames_discarded(), 0u);
  EXPECT_EQ(Starts(a, 0, 160), (std::vector<int64_t>{0}));
  a.Break();  // frames 151-160 were the next clip's first 10
  EXPECT_EQ(a.frames_discarded(), 10u);
  EXPECT_EQ(Starts(a, 0, 20).size(), 0u);
  a.Break();  // before the first clip: all 20
  EXPECT_EQ(a.frames_discarded(), 30u);
  EXPECT_EQ(a.breaks(), 3u);
}

TEST(ClipAssemblerTest, NonConsecutiveTickBreaks) {
  ClipAssembler a(5, 5);
  EXPECT_TRUE(Starts(a, 0, 4).empty());
  // Tick 10 does not follow 3: the 4 frames are dropped, the clip restarts at 10.
  EXPECT_EQ(Starts(a, 10, 16), (std::vector<int64_t>{10}));
  EXPECT_EQ(a.breaks(), 1u);
}

TEST(ClipAssemblerTest, RejectsBadSettings) {
  EXPECT_THROW(ClipAssembler(0, 1), std::invalid_argument);
  EXPECT_THROW(ClipAssembler(30, 0), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sensors
