#include "sensors/wind_plot.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

bool HasColourInColumnRange(const cv::Mat& img, int x0, int x1, int y0, int y1, const cv::Scalar& c) {
  for (int y = std::max(0, y0); y <= std::min(img.rows - 1, y1); ++y) {
    for (int x = std::max(0, x0); x <= std::min(img.cols - 1, x1); ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      if (p[0] == c[0] && p[1] == c[1] && p[2] == c[2]) return true;
    }
  }
  return false;
}

// Vertical grid lines in a plot DrawWindPlot drew: columns strictly inside the plot frame whose
// pixels are mostly the grid's grey (a horizontal grid line greys one pixel of a column; series
// may cross a grid column but cover little of it).
int GridColumns(const cv::Mat& img) {
  const int left = kPlotLeft, right = img.cols - kPlotRight, top = kPlotTop, bottom = img.rows - kPlotBottom;
  const cv::Vec3b grey(kPlotGrid[0], kPlotGrid[1], kPlotGrid[2]);
  int lines = 0;
  for (int x = left + 1; x < right; ++x) {
    int n = 0;
    for (int y = top + 1; y < bottom; ++y) n += img.at<cv::Vec3b>(y, x) == grey;
    lines += 2 * n > bottom - top - 1;
  }
  return lines;
}

TEST(WindHistoryTest, MeanOverWindowAndForgetting) {
  WindHistory h(100.0);
  for (int i = 0; i <= 200; ++i) h.Add({static_cast<double>(i), static_cast<double>(i % 2), 0.0});
  EXPECT_EQ(h.samples().front().t, 100.0);  // older than span forgotten
  int n = 0;
  // (190, 200]: t = 191..200, speeds 1,0,1,0,... -> mean 0.5
  EXPECT_DOUBLE_EQ(h.Mean(200.0, 10.0, &n), 0.5);
  EXPECT_EQ(n, 10);
  EXPECT_TRUE(std::isnan(h.Mean(50.0, 10.0, &n)));
  EXPECT_EQ(n, 0);
  h.Add({201.0, kNaN, 0.0});  // no reading: ignored
  EXPECT_EQ(h.back().t, 200.0);
  h.Add({197.5, 4.0, 0.0});  // a little out of order (two sources, jitter): kept, in its place
  ASSERT_EQ(h.samples().size(), 102u);
  EXPECT_EQ(h.back().t, 200.0);
  EXPECT_EQ(h.samples()[h.samples().size() - 4].t, 197.5);
  EXPECT_DOUBLE_EQ(h.Mean(200.0, 3.0, &n), (4.0 + 0 + 1 + 0) / 4);  // (197, 200]: 197.5, 198, 199, 200
  h.Add({5.0, 2.0, 0.0});  // clock jumped back (bag replayed again): start afresh
  EXPECT_EQ(h.samples().size(), 1u);
}

// One absurd speed (a CSV anemometer's 1e20) or a report whose first stamp is 0 must not turn the
// grid loops into millions of lines (the redraw hung).
TEST(WindPlotTest, AbsurdValuesAndSpansDrawPromptly) {
  WindHistory est(1e10), anem(1e10);
  est.Add({0.0, 3.0, 0.2});
  est.Add({1.7e9, 1e20, 1e19});
  anem.Add({1.7e9, 4.0, 0.0});
  EXPECT_EQ(WindPlotAxisMax(1e20), kWindPlotAxisCap);
  EXPECT_EQ(WindPlotRow(1e20, kWindPlotAxisCap, 240), WindPlotRow(kWindPlotAxisCap, kWindPlotAxisCap, 240));
  // The vertical grid step widens with the window so that at most ~12 lines are drawn. Checked on
  // a window (1e5 s, ~1700 lines at the 60 s step) that draws quickly even without the widening,
  // so a regression fails here instead of hanging on the 1.7e9 s span below.
  const int w = 320, h = 200;
  WindHistory day(1e6), none(1e6);
  day.Add({1e5, 3.0, 0.0});
  const int day_lines = GridColumns(DrawWindPlot(day, none, 1e5, 1e5, w, h));
  ASSERT_GE(day_lines, 2);  // the grid is there, and is counted
  ASSERT_LE(day_lines, 13);
  // Hung before (the step stayed 60 s: 2.8e7 lines): a regression of the widening is caught just
  // above; one elsewhere would show as this test timing out (CTest's 900 s).
  const cv::Mat img = DrawWindPlot(est, anem, 1.7e9, 1.7e9, w, h, 0.0);
  EXPECT_EQ(img.rows, h);
  const int span_lines = GridColumns(img);
  EXPECT_GE(span_lines, 2);
  EXPECT_LE(span_lines, 13);
  EXPECT_THROW(DrawWindPlot(est, anem, 1.7e9, std::numeric_limits<double>::infinity(), 320, 200),
               std::invalid_argument);
}

TEST(WindPlotTest, SummaryText) {
  EXPECT_EQ(WindSummaryText(3.42, 0.31, 3.18, 60), "estimate 3.4 \xC2\xB1 0.3 m/s | anemometer 3.2 m/s (60 s mean)");
  EXPECT_EQ(WindSummaryText(kNaN, kNaN, 2.0, 30), "estimate -- | anemometer 2.0 m/s (30 s mean)");
  EXPECT_EQ(WindSummaryText(1.0, kNaN, kNaN, 60), "estimate 1.0 m/s | anemometer -- (60 s mean)");
  EXPECT_EQ(WindSummaryText(3.42, 0.31, 3.18, 60, 3.64),
            "estimate 3.4 \xC2\xB1 0.3 m/s, 60 s mean 3.6 | anemometer 3.2 m/s (60 s mean)");
  EXPECT_EQ(WindSummaryText(kNaN, kNaN, 2.0, 30, 2.5), "estimate -- | anemometer 2.0 m/s (30 s mean)");
  // Early in a session the means span less than the window, and say so.
  EXPECT_EQ(WindSummaryText(6.2, 0.4, 4.3, 60, 6.2, 13.6, 14.2),
            "estimate 6.2 \xC2\xB1 0.4 m/s, 14 of 60 s mean 6.2 | anemometer 4.3 m/s (14 of 60 s mean)");
  EXPECT_EQ(WindSummaryText(6.2, 0.4, 4.3, 60, 6.2, 59.5, 60.0),
            "estimate 6.2 \xC2\xB1 0.4 m/s, 60 s mean 6.2 | anemometer 4.3 m/s (60 s mean)");
}

TEST(WindPlotTest, SpanIsWhatTheWindowsSamplesCover) {
  WindHistory h(300);
  EXPECT_EQ(h.Span(100, 60), 0.0);
  for (int t = 90; t <= 100; ++t) h.Add({static_cast<double>(t), 3.0});
  EXPECT_DOUBLE_EQ(h.Span(100, 60), 10.0);
  for (int t = 0; t < 90; ++t) h.Add({static_cast<double>(t), 3.0});
  EXPECT_DOUBLE_EQ(h.Span(100, 60), 59.0);  // the oldest in (40, 100] is 41
}

// The arrow stays in the monitor's ±5 m view: 0.3 m per m/s, at most 4.5 m.
TEST(WindPlotTest, TheWindArrowFitsTheView) {
  EXPECT_DOUBLE_EQ(WindArrowScale(5.0, 0.0, 0.0), kWindArrowMetresPerMps);
  EXPECT_DOUBLE_EQ(12.4 * WindArrowScale(12.4, 0.0, 0.0), 3.72);
  EXPECT_NEAR(30.0 * WindArrowScale(0.0, -30.0, 0.0), kWindArrowMaxLength, 1e-12);
  EXPECT_EQ(WindArrowScale(0.0, 0.0, 0.0), 0.0);
  EXPECT_EQ(WindArrowScale(kNaN, 1.0, 0.0), 0.0);
}

TEST(WindPlotTest, SeriesDrawnAtTheirSpeeds) {
  WindHistory est(300), anem(300);
  for (int i = 0; i <= 60; ++i) {
    est.Add({1000.0 + i, 6.0, 0.0});
    anem.Add({1000.0 + i, 2.0, 0.0});
  }
  const int w = 400, h = 240;
  const cv::Mat img = DrawWindPlot(est, anem, 1060.0, 60.0, w, h);
  ASSERT_EQ(img.type(), CV_8UC3);
  ASSERT_EQ(img.rows, h);
  const double y_max = WindPlotAxisMax(6.0);
  EXPECT_GE(y_max, 6.0);
  const int r_est = WindPlotRow(6.0, y_max, h), r_anem = WindPlotRow(2.0, y_max, h);
  EXPECT_LT(r_est, r_anem);  // faster wind is higher up
  // In the middle of the plot each colour sits on its own row and not on the other's.
  EXPECT_TRUE(HasColourInColumnRange(img, 180, 220, r_est - 1, r_est + 1, kEstimateColour));
  EXPECT_TRUE(HasColourInColumnRange(img, 180, 220, r_anem - 1, r_anem + 1, kAnemometerColour));
  EXPECT_FALSE(HasColourInColumnRange(img, 180, 220, r_anem - 1, r_anem + 1, kEstimateColour));
  EXPECT_FALSE(HasColourInColumnRange(img, 180, 220, r_est - 1, r_est + 1, kAnemometerColour));
}

// An anemometer at 1 Hz that was unplugged for 20 s: its line breaks across the outage (a line
// there showed readings never made), and a series at its own slower rhythm does not.
TEST(WindPlotTest, TheLineBreaksAcrossAnOutage) {
  WindHistory est(300), anem(300);
  for (int i = 0; i <= 60; ++i) {
    if (i <= 20 || i >= 40) anem.Add({1000.0 + i, 2.0, 0.0});
    if (i % 10 == 0) est.Add({1000.0 + i, 6.0, 0.0});  // every 10 s, no outage
  }
  EXPECT_DOUBLE_EQ(WindSeriesGap(anem, 1060.0, 60.0), 3.0);
  EXPECT_DOUBLE_EQ(WindSeriesGap(est, 1060.0, 60.0), 30.0);
  // Readings in pairs 2 ms apart (relative and true wind), one pair a second: the rhythm is the
  // second, for an odd or an even number of steps alike (the median of all steps flipped).
  for (int n : {60, 61}) {
    WindHistory pairs(300);
    for (int i = 0; i < n; ++i) pairs.Add({1000.0 + i / 2 + (i % 2) * 0.002, 2.0, 0.0});
    EXPECT_NEAR(WindSeriesGap(pairs, 1060.0, 60.0), 2.994, 1e-9) << n;
  }
  WindHistory two(300);
  two.Add({1000.0, 1.0, 0.0});
  two.Add({1001.0, 1.0, 0.0});
  EXPECT_TRUE(std::isinf(WindSeriesGap(two, 1060.0, 60.0)));
  const int w = 400, h = 240;
  const cv::Mat img = DrawWindPlot(est, anem, 1060.0, 60.0, w, h);
  const double y_max = WindPlotAxisMax(6.0);
  const int r_anem = WindPlotRow(2.0, y_max, h), r_est = WindPlotRow(6.0, y_max, h);
  // Columns of t = 1030 (the outage's middle) and of t = 1010 and 1050 (readings around it).
  auto column = [&](double t) {
    return static_cast<int>(std::lround(w - kPlotRight - (1060.0 - t) / 60.0 * (w - kPlotRight - kPlotLeft)));
  };
  EXPECT_FALSE(HasColourInColumnRange(img, column(1027), column(1033), r_anem - 1, r_anem + 1, kAnemometerColour));
  EXPECT_TRUE(HasColourInColumnRange(img, column(1008), column(1012), r_anem - 1, r_anem + 1, kAnemometerColour));
  EXPECT_TRUE(HasColourInColumnRange(img, column(1048), column(1052), r_anem - 1, r_anem + 1, kAnemometerColour));
  // Between two estimates 10 s apart, the line is drawn.
  EXPECT_TRUE(HasColourInColumnRange(img, column(1034), column(1036), r_est - 1, r_est + 1, kEstimateColour));
}

TEST(WindPlotTest, OnlyTheWindowIsShown) {
  WindHistory est(1000), anem(1000);
  // Estimates only long before the window: nothing of them may appear in the plot area.
  for (int i = 0; i < 10; ++i) est.Add({static_cast<double>(i), 3.0, 0.5});
  anem.Add({500.0, 1.0, 0.0});
  const cv::Mat img = DrawWindPlot(est, anem, 500.0, 60.0, 320, 200);
  // Legend swatches are in the top margin (rows < 22); the plot area must have no estimate colour.
  EXPECT_FALSE(HasColourInColumnRange(img, 0, img.cols - 1, 22, img.rows - 1, kEstimateColour));
  EXPECT_TRUE(HasColourInColumnRange(img, 0, img.cols - 1, 22, img.rows - 1, kAnemometerColour));
  // Samples long before the window land far off the image, where OpenCV clips them whether the
  // series is cut to the window or not. Samples every second just before it would land in the
  // left margin (the y labels' room, x < 44) and draw over the labels: none may show there. The
  // first sample inside the window (t = 440, at x = 44) has a dot of radius 2, reaching x = 42.
  WindHistory near(1000), none(1000);
  for (int t = 430; t <= 500; ++t) near.Add({static_cast<double>(t), 3.0, 0.0});
  const cv::Mat edge = DrawWindPlot(near, none, 500.0, 60.0, 320, 200);
  EXPECT_FALSE(HasColourInColumnRange(edge, 0, kPlotLeft - 3, kPlotTop, edge.rows - 1, kEstimateColour));
  EXPECT_TRUE(HasColourInColumnRange(edge, kPlotLeft - 2, edge.cols - 1, kPlotTop, edge.rows - 1, kEstimateColour));
}

TEST(WindPlotTest, BadArguments) {
  WindHistory a(10), b(10);
  EXPECT_THROW(DrawWindPlot(a, b, 0.0, 60.0, 100, 200), std::invalid_argument);
  EXPECT_THROW(DrawWindPlot(a, b, 0.0, 0.0, 320, 200), std::invalid_argument);
  EXPECT_NO_THROW(DrawWindPlot(a, b, 0.0, 60.0, 320, 200));
}

}  // namespace
}  // namespace clothwind::sensors
