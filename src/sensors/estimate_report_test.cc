#include "sensors/estimate_report.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sensors/wind_plot.h"

namespace clothwind::sensors {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(EstimateReportTest, MetricsOverLabelledRowsOnly) {
  // Errors +0.3, -0.6, +0.9 on three labelled clips; one clip without a label, one NaN estimate.
  const std::vector<EstimateRow> rows = {
      {1, 10.0, 3.3, 0.2, 3.0, 0.010}, {2, 11.2, 4.4, 0.2, 5.0, 0.020}, {3, 12.4, 6.9, kNaN, 6.0, 0.030},
      {4, 13.6, 2.0, 0.1, kNaN, 0.040}, {5, 14.8, kNaN, kNaN, 2.0, 0.050}};
  const EstimateSummary s = SummariseEstimates(rows);
  EXPECT_EQ(s.count, 5);
  EXPECT_EQ(s.compared, 3);
  EXPECT_NEAR(s.rmse, std::sqrt((0.09 + 0.36 + 0.81) / 3), 1e-12);
  EXPECT_NEAR(s.acc05, 1.0 / 3, 1e-12);  // only +0.3 is within 0.5 m/s
  EXPECT_NEAR(s.bias, 0.2, 1e-12);
  EXPECT_NEAR(s.mean_label, 14.0 / 3, 1e-12);
  EXPECT_NEAR(s.mean_latency, 0.030, 1e-12);
  EXPECT_DOUBLE_EQ(s.max_latency, 0.050);
}

TEST(EstimateReportTest, TrailingMeanAveragesTheGustsOfSingleClips) {
  // Estimates 6, 4, 6, 4 (given out of order) at 0, 1, 2, 3 s against a steady label of 5: every
  // clip is 1 m/s off, but a 2 s trailing mean (this row and the one before) is exact from the
  // second row on; the first row has only itself.
  const std::vector<EstimateRow> rows = {
      {3, 2.0, 6.0, 0.5, 5.0, 0.0}, {1, 0.0, 6.0, 0.5, 5.0, 0.0}, {4, 3.0, 4.0, 0.5, 5.0, 0.0}, {2, 1.0, 4.0, 0.5, 5.0, 0.0}};
  const EstimateSummary s = SummariseEstimates(rows, 2.0);
  EXPECT_DOUBLE_EQ(s.rmse, 1.0);
  EXPECT_DOUBLE_EQ(s.window, 2.0);
  EXPECT_DOUBLE_EQ(s.window_rmse, 0.5);  // sqrt((1 + 0 + 0 + 0) / 4)
  EXPECT_DOUBLE_EQ(s.window_acc05, 0.75);
  EXPECT_DOUBLE_EQ(s.window_bias, 0.25);
  // A window of one spacing holds the row alone (it is open at its start): the per-clip figures.
  const EstimateSummary one = SummariseEstimates(rows, 1.0);
  EXPECT_DOUBLE_EQ(one.window_rmse, one.rmse);
  EXPECT_DOUBLE_EQ(one.window_bias, one.bias);
  // Rows without a label or estimate are left out as in the per-clip figures, and a NaN estimate
  // does not poison the mean of its neighbours.
  std::vector<EstimateRow> holes = rows;
  holes.push_back({5, 3.5, kNaN, kNaN, 5.0, 0.0});
  holes.push_back({6, 3.6, 5.0, 0.5, kNaN, 0.0});
  const EstimateSummary h = SummariseEstimates(holes, 2.0);
  EXPECT_EQ(h.compared, 4);
  EXPECT_DOUBLE_EQ(h.window_rmse, 0.5);
  EXPECT_THROW(SummariseEstimates(rows, 0.0), std::invalid_argument);
  // The default window is the field protocol's minute, and the table and JSON carry the figures.
  EXPECT_DOUBLE_EQ(SummariseEstimates(rows).window, 60.0);
  EXPECT_NE(EstimateTable(rows, 0.0).find("trailing 60 s mean"), std::string::npos);
  EXPECT_TRUE(EstimateJson(rows).contains("window_rmse"));
}

TEST(EstimateReportTest, NoLabelsGiveNaNNotZero) {
  const EstimateSummary s = SummariseEstimates({{1, 1.0, 2.0, 0.1, kNaN, 0.0}});
  EXPECT_EQ(s.compared, 0);
  EXPECT_TRUE(std::isnan(s.rmse));
  EXPECT_TRUE(std::isnan(s.acc05));
  EXPECT_TRUE(std::isnan(s.window_rmse));
  EXPECT_TRUE(std::isnan(SummariseEstimates({}).rmse));
}

TEST(EstimateReportTest, TableSortedByTimeWithSummary) {
  const std::vector<EstimateRow> rows = {{7, 112.0, 5.0, 0.25, 4.0, 0.02}, {6, 110.8, 3.0, 0.25, 3.5, 0.02}};
  const std::string table = EstimateTable(rows, 100.0);
  const size_t a = table.find("\n    6 "), b = table.find("\n    7 ");
  ASSERT_NE(a, std::string::npos) << table;
  ASSERT_NE(b, std::string::npos) << table;
  EXPECT_LT(a, b);
  EXPECT_NE(table.find("10.80"), std::string::npos) << table;  // time since t0
  EXPECT_NE(table.find("+1.00"), std::string::npos) << table;  // error of clip 7
  EXPECT_NE(table.find("RMSE 0.791 m/s"), std::string::npos) << table;  // sqrt((1 + 0.25) / 2)
  EXPECT_NE(table.find("Acc@0.5 0.500"), std::string::npos) << table;
}

// Columns line up on screen: every row as wide as the heading in characters (UTF-8 "±" is two
// bytes and one character), with and without a std.
TEST(EstimateReportTest, TableColumnsLineUpOnScreen) {
  const std::vector<EstimateRow> rows = {{1, 101.0, 5.0, 0.25, 4.0, 0.02}, {2, 102.0, 3.0, kNaN, 3.5, 0.02}};
  const std::string table = EstimateTable(rows, 100.0);
  auto characters = [](const std::string& line) {
    size_t n = 0;
    for (unsigned char c : line) n += (c & 0xC0) != 0x80;  // count all but continuation bytes
    return n;
  };
  std::vector<std::string> lines;
  size_t start = 0;
  for (size_t end; (end = table.find('\n', start)) != std::string::npos; start = end + 1)
    lines.push_back(table.substr(start, end - start));
  ASSERT_GE(lines.size(), 3u) << table;
  EXPECT_EQ(characters(lines[1]), characters(lines[0])) << table;
  EXPECT_EQ(characters(lines[2]), characters(lines[0])) << table;
  EXPECT_NE(lines[1].find("\xC2\xB1"), std::string::npos) << table;
}

TEST(EstimateReportTest, JsonRoundTripsAndWritesNaNAsNull) {
  const std::vector<EstimateRow> rows = {{2, 2.0, 1.5, kNaN, 1.0, 0.01}, {1, 1.0, 1.0, 0.3, kNaN, 0.02}};
  const nlohmann::json j = nlohmann::json::parse(EstimateJson(rows).dump());
  ASSERT_EQ(j["estimates"].size(), 2u);
  EXPECT_EQ(j["estimates"][0]["sequence"], 1);  // sorted by time
  EXPECT_TRUE(j["estimates"][0]["reference"].is_null());
  EXPECT_TRUE(j["estimates"][1]["speed_std"].is_null());
  EXPECT_DOUBLE_EQ(j["rmse"].get<double>(), 0.5);
  EXPECT_EQ(j["compared"], 1);
}

TEST(EstimateReportTest, TheTrailingMeanUsesTheWindowItIsGiven) {
  // The report passes the clips' label window (clip_report used 60 s whatever the labels' were).
  // Estimates alternate 1 and 3 m/s a second around a label of 2: over 1 s the trailing mean is
  // each estimate itself (error 1), over 60 s it settles near 2.
  std::vector<EstimateRow> rows;
  for (int i = 0; i < 60; ++i) rows.push_back({static_cast<uint64_t>(i), 1000.0 + i, i % 2 ? 3.0 : 1.0, 0.1, 2.0, 0.01});
  const nlohmann::json one = EstimateJson(rows, 1.0), sixty = EstimateJson(rows);
  EXPECT_DOUBLE_EQ(one["window"].get<double>(), 1.0);
  EXPECT_NEAR(one["window_rmse"].get<double>(), 1.0, 1e-9);
  EXPECT_DOUBLE_EQ(sixty["window"].get<double>(), 60.0);
  EXPECT_LT(sixty["window_rmse"].get<double>(), 0.3);
  EXPECT_NE(EstimateTable(rows, 1000.0, 1.0), EstimateTable(rows, 1000.0));
}

TEST(EstimateReportTest, AnAbsurdSpeedKeepsItsRowWholeAndTheSummaryAfterIt) {
  // 1e300 printed 301 digits into a 200-byte line: the row lost its end of line and the summary
  // line after it was cut short.
  const std::vector<EstimateRow> rows = {{1, 1000.0, 1e300, 0.3, 2.0, 0.01}, {2, 1001.0, 2.5, 0.3, 2.0, 0.01}};
  const std::string table = EstimateTable(rows, 1000.0);
  const size_t row = table.find("1e+300") != std::string::npos ? table.find("1e+300") : table.find("00000000000000");
  ASSERT_NE(row, std::string::npos) << table;
  const size_t end_of_row = table.find('\n', row);
  ASSERT_NE(end_of_row, std::string::npos);
  EXPECT_NE(table.find("    2  ", end_of_row), std::string::npos) << table;  // the next row follows
  EXPECT_NE(table.find("estimates: 2"), std::string::npos) << table;
  EXPECT_NE(table.find("trailing 60 s mean"), std::string::npos) << table;  // the summary's second line, whole
  EXPECT_EQ(table.back(), '\n');
}

TEST(EstimateReportTest, PlotShowsBothSeriesAtTheirSpeeds) {
  std::vector<EstimateRow> rows;
  for (int i = 0; i < 60; ++i) rows.push_back({static_cast<uint64_t>(i), 1000.0 + 1.2 * i, 7.0, 0.0, 2.0, 0.01});
  const int w = 800, h = 360;
  const cv::Mat img = DrawEstimatePlot(rows, 998.8, w, h);
  ASSERT_EQ(img.type(), CV_8UC3);
  ASSERT_EQ(img.cols, w);
  const double y_max = WindPlotAxisMax(7.0);
  auto row_has_in = [&](const cv::Mat& image, int y, const cv::Scalar& c) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int x = w / 3; x < 2 * w / 3; ++x) {
        const cv::Vec3b p = image.at<cv::Vec3b>(y + dy, x);
        if (p[0] == c[0] && p[1] == c[1] && p[2] == c[2]) return true;
      }
    }
    return false;
  };
  auto row_has = [&](int y, const cv::Scalar& c) { return row_has_in(img, y, c); };
  EXPECT_TRUE(row_has(WindPlotRow(7.0, y_max, h), kEstimateColour));
  EXPECT_TRUE(row_has(WindPlotRow(2.0, y_max, h), kAnemometerColour));
  EXPECT_FALSE(row_has(WindPlotRow(2.0, y_max, h), kEstimateColour));
  EXPECT_THROW(DrawEstimatePlot({}, 0.0, w, h), std::invalid_argument);
  // An estimate of a clip stamped 0 and a t0 of 0 (no clip reached the report): left out and
  // taken from the rows, so the plot still shows the session, not 1.7e9 s of empty axis.
  rows.push_back({99, 0.0, 50.0, 0.0, 2.0, 0.01});
  const cv::Mat same = DrawEstimatePlot(rows, 0.0, w, h);
  EXPECT_TRUE(row_has_in(same, WindPlotRow(7.0, y_max, h), kEstimateColour));
  EXPECT_TRUE(row_has_in(same, WindPlotRow(2.0, y_max, h), kAnemometerColour));
  EXPECT_THROW(DrawEstimatePlot({{1, 0.0, 3.0, 0.0, 2.0, 0.01}}, 0.0, w, h), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sensors
