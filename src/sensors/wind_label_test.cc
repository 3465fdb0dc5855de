#include "sensors/wind_label.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(WindLabelTest, MeanStdCountOverWindowInclusive) {
  // Readings at 0..10 s with speed = stamp; the window [4, 10] holds 4..10.
  std::vector<LabelReading> readings;
  for (int i = 0; i <= 10; ++i) readings.push_back({double(i), double(i), kNaN});
  const WindLabel l = ComputeWindLabel(readings, 10.0, 6.0);
  EXPECT_EQ(l.count, 7u);
  EXPECT_DOUBLE_EQ(l.mean, 7.0);
  EXPECT_NEAR(l.std, 2.0, 1e-12);  // population std of 4..10
  EXPECT_DOUBLE_EQ(l.first_stamp, 4.0);
  EXPECT_DOUBLE_EQ(l.last_stamp, 10.0);
  EXPECT_TRUE(std::isnan(l.direction_mean));
}

TEST(WindLabelTest, EmptyWindowIsNaN) {
  const WindLabel l = ComputeWindLabel({{100.0, 3.0, 0.0}}, 50.0, 10.0);
  EXPECT_EQ(l.count, 0u);
  EXPECT_TRUE(std::isnan(l.mean));
  EXPECT_TRUE(std::isnan(l.std));
}

TEST(WindLabelTest, CircularMeanAcrossPi) {
  // +170 and -170 degrees average to 180, not 0.
  const double d = 170.0 * M_PI / 180.0;
  const WindLabel l = ComputeWindLabel({{1.0, 2.0, d}, {2.0, 2.0, -d}}, 2.0, 5.0);
  EXPECT_NEAR(std::fabs(l.direction_mean), M_PI, 1e-12);
}

TEST(WindLabelTest, TheLabelNamesItsInstrumentsAndCountsRelativeReadings) {
  // Two anemometers on one topic (a masthead Gill giving apparent wind, a station's MWV giving
  // true wind): the label counts each one's readings in the window, leaves out a reading outside
  // it and one without a speed, and counts the relative ones; WindLabeller agrees.
  std::vector<LabelReading> readings = {
      {1.0, 3.0, 0.1, "gill", "mast", true},      {2.0, 3.2, 0.1, "nmea_mwv", "station", false},
      {3.0, 3.1, 0.1, "gill", "mast", true},      {4.0, kNaN, 0.1, "nmea_xdr", "other", false},
      {-9.0, 3.0, 0.1, "csv", "old", false},      {5.0, 3.3, 0.1, "nmea_mwv", "station", false},
      {6.0, 3.3, 0.1, "gill", "mast", true}};
  const WindLabel l = ComputeWindLabel(readings, 6.0, 6.0);
  EXPECT_EQ(l.count, 5u);
  const std::vector<WindLabelSource> want = {{"gill", "mast", 3}, {"nmea_mwv", "station", 2}};
  EXPECT_EQ(l.sources, want);
  EXPECT_EQ(l.relative_count, 3u);
  WindLabeller labeller(6.0);
  for (const auto& r : readings) labeller.Add(r);
  EXPECT_EQ(labeller.Label(6.0).sources, want);
  EXPECT_EQ(labeller.Label(6.0).relative_count, 3u);
  EXPECT_TRUE(ComputeWindLabel(readings, 50.0, 1.0).sources.empty()) << "no reading, no instrument";
}

TEST(WindLabelTest, LabellerMatchesByStampNotArrival) {
  // The same readings added shuffled give the label of the sorted list, over any window.
  std::vector<LabelReading> readings;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> speed(0.5, 8.0), dir(-M_PI, M_PI);
  for (int i = 0; i < 200; ++i) readings.push_back({1000.0 + i + 0.05, speed(rng), dir(rng)});
  std::vector<LabelReading> shuffled = readings;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  WindLabeller labeller(60.0);
  for (const auto& r : shuffled) labeller.Add(r);
  for (double end : {1010.0, 1070.3, 1150.05, 1199.9}) {
    const WindLabel a = labeller.Label(end), b = ComputeWindLabel(readings, end, 60.0);
    EXPECT_EQ(a.count, b.count) << end;
    EXPECT_NEAR(a.mean, b.mean, 1e-12);
    EXPECT_NEAR(a.std, b.std, 1e-12);
    EXPECT_NEAR(a.direction_mean, b.direction_mean, 1e-12);
  }
  EXPECT_EQ(labeller.Label(1070.3).count, 60u);  // stamps 1011.05 .. 1070.05
}

TEST(WindLabelTest, LateReadingCountsAndPruneForgets) {
  WindLabeller labeller(10.0);
  labeller.Add({5.0, 1.0, kNaN});
  labeller.Add({7.0, 3.0, kNaN});
  EXPECT_DOUBLE_EQ(labeller.Label(8.0).mean, 2.0);
  labeller.Add({6.0, 5.0, kNaN});  // arrives last, stamped in between
  EXPECT_DOUBLE_EQ(labeller.Label(8.0).mean, 3.0);
  EXPECT_EQ(labeller.Label(8.0).count, 3u);
  EXPECT_FALSE(labeller.Add({kNaN, 1.0, 0.0}));
  EXPECT_FALSE(labeller.Add({9.0, kNaN, 0.0}));
  labeller.Prune(6.5);
  EXPECT_EQ(labeller.size(), 1u);
  EXPECT_DOUBLE_EQ(labeller.newest_stamp(), 7.0);
}

}  // namespace
}  // namespace clothwind::sensors
