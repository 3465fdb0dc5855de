#include "sensors/clip_report.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

ClipRow Clip(uint64_t sequence, double start, double mean, uint32_t count) {
  ClipRow r;
  r.sequence = sequence;
  r.start = start;
  r.end = start + 29.0 / 25;
  r.frames = 30;
  r.mean = mean;
  r.std = count > 0 ? 0.2 : kNaN;
  r.count = count;
  r.width = r.height = 300;
  return r;
}

TEST(ClipReportTest, MaxSpacingErrorIsTheWorstIntervalsDistanceFromTheFrameRate) {
  EXPECT_EQ(MaxSpacingError({}, 25), 0.0);
  EXPECT_EQ(MaxSpacingError({5.0}, 25), 0.0);
  EXPECT_NEAR(MaxSpacingError({0.0, 0.04, 0.08}, 25), 0.0, 1e-12);
  EXPECT_NEAR(MaxSpacingError({0.0, 0.04, 0.09, 0.12}, 25), 0.01, 1e-12);  // 0.05 and 0.03 both 0.01 off
  // A corrupt stamp (ROS time's end) is a huge error, not a throw.
  EXPECT_GT(MaxSpacingError({100.0, 4294967295.0}, 25), 1e9);
}

TEST(ClipReportTest, TheOriginIsTheEarliestClipStartElseTheFirstEstimate) {
  std::vector<ClipRow> clips = {Clip(2, 110.0, 4, 3), Clip(1, 100.0, 4, 3)};
  EXPECT_EQ(ReportOrigin(clips, {}), 100.0);
  clips[1].start = kNaN;  // a clip without frame stamps has no start
  EXPECT_EQ(ReportOrigin(clips, {}), 110.0);
  EXPECT_EQ(ReportOrigin({}, {}), 0.0);
  EstimateRow unstamped, first, second;
  unstamped.end = 0;
  first.end = 205.0;
  second.end = 200.0;
  EXPECT_EQ(ReportOrigin({}, {unstamped, first, second}), 205.0);  // the first with a time
  clips = {Clip(1, kNaN, 4, 3)};
  EXPECT_EQ(ReportOrigin(clips, {first}), 205.0);
}

TEST(ClipReportTest, UnestimatedCountsClipsWithoutAnEstimateOfTheirNumber) {
  const std::vector<ClipRow> clips = {Clip(1, 1, 4, 3), Clip(2, 2, 4, 3), Clip(3, 3, 4, 3)};
  EstimateRow a, b;
  a.sequence = 3;
  b.sequence = 1;
  EXPECT_EQ(Unestimated(clips, {a, b}), 1u);
  EXPECT_EQ(Unestimated(clips, {}), 3u);
  EXPECT_EQ(Unestimated({}, {a}), 0u);
}

TEST(ClipReportTest, TheTableListsEachClipAndTotalsTheLabelledOnes) {
  const std::vector<ClipRow> clips = {Clip(7, 100.0, 4.0, 3), Clip(8, 101.2, kNaN, 0), Clip(9, 102.4, 6.0, 5)};
  const std::string table = ClipTable(clips, 100.0, {25.0, 60.0, 12.5});
  // A header, a line per clip, the totals.
  EXPECT_EQ(std::count(table.begin(), table.end(), '\n'), 5) << table;
  EXPECT_NE(table.find("    7         0.000         1.160"), std::string::npos) << table;
  EXPECT_NE(table.find("totals: 3 clips, 90 frames at 25.0 fps (300x300), 2 labelled (label window 60 s, mean of "
                       "labels 5.000 m/s), first to last frame 3.56 s"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("wall 12.5 s"), std::string::npos) << table;
  // No clip: a header and totals, the mean of no labels nan.
  const std::string empty = ClipTable({}, 0.0, {});
  EXPECT_NE(empty.find("totals: 0 clips, 0 frames at 0.0 fps (0x0), 0 labelled"), std::string::npos) << empty;
  EXPECT_NE(empty.find("mean of labels nan m/s"), std::string::npos) << empty;
}

TEST(ClipReportTest, JsonCarriesEveryClipAndWritesAMissingLabelAsNull) {
  const std::vector<ClipRow> clips = {Clip(7, 100.0, 4.0, 3), Clip(8, 101.2, kNaN, 0)};
  const nlohmann::json j = ClipJson(clips, {25.0, 60.0, 12.5});
  ASSERT_EQ(j.at("clips").size(), 2u);
  EXPECT_EQ(j.at("clips")[0].at("sequence"), 7u);
  EXPECT_EQ(j.at("clips")[0].at("wind_mean"), 4.0);
  EXPECT_TRUE(j.at("clips")[1].at("wind_mean").is_null());
  EXPECT_TRUE(j.at("clips")[1].at("wind_std").is_null());
  EXPECT_EQ(j.at("total_clips"), 2u);
  EXPECT_EQ(j.at("total_frames"), 60u);
  EXPECT_EQ(j.at("labelled_clips"), 1u);
  EXPECT_EQ(j.at("frame_rate"), 25.0);
  EXPECT_EQ(j.at("label_window"), 60.0);
  EXPECT_EQ(j.at("wall_seconds"), 12.5);
  // It parses back as written (a NaN written as a number would come back as null, not equal).
  EXPECT_EQ(nlohmann::json::parse(j.dump()), j);
}

}  // namespace
}  // namespace clothwind::sensors
