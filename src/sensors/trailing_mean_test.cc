#include "sensors/trailing_mean.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(TrailingMeanTest, WindowIsOpenAtItsStartAndClosedAtItsEnd) {
  TrailingMean m(2.0);
  EXPECT_EQ(m.Count(), 0u);
  EXPECT_TRUE(std::isnan(m.Mean()));
  EXPECT_TRUE(std::isnan(m.Std()));
  EXPECT_TRUE(std::isnan(m.Oldest()));
  m.Add(0.0, 6.0, 0.3);
  EXPECT_DOUBLE_EQ(m.Mean(), 6.0);
  EXPECT_DOUBLE_EQ(m.Std(), 0.3);
  m.Add(1.0, 4.0, 0.4);
  EXPECT_EQ(m.Count(), 2u);
  EXPECT_DOUBLE_EQ(m.Mean(), 5.0);
  EXPECT_NEAR(m.Std(), std::sqrt((0.09 + 0.16) / 2), 1e-12);  // not divided by sqrt(2)
  m.Add(2.0, 8.0, 0.3);  // t = 0 drops out: (0, 2]
  EXPECT_EQ(m.Count(), 2u);
  EXPECT_DOUBLE_EQ(m.Mean(), 6.0);
  EXPECT_DOUBLE_EQ(m.Oldest(), 1.0);
  m.Add(10.0, 1.0, 0.1);  // a gap longer than the window leaves only the new value
  EXPECT_EQ(m.Count(), 1u);
  EXPECT_DOUBLE_EQ(m.Mean(), 1.0);
  EXPECT_THROW(TrailingMean(0.0), std::invalid_argument);
  EXPECT_THROW(TrailingMean{kNaN}, std::invalid_argument);
}

TEST(TrailingMeanTest, NonFiniteValuesAndMissingStdsAreHandled) {
  TrailingMean m(10.0);
  m.Add(0.0, 3.0, 0.2);
  m.Add(1.0, kNaN, kNaN);  // a failed estimate: left out, the mean carries on
  EXPECT_EQ(m.Count(), 1u);
  EXPECT_DOUBLE_EQ(m.Mean(), 3.0);
  EXPECT_DOUBLE_EQ(m.Std(), 0.2);
  m.Add(2.0, 5.0, kNaN);  // an estimate without a std: the mean has none either ...
  EXPECT_DOUBLE_EQ(m.Mean(), 4.0);
  EXPECT_TRUE(std::isnan(m.Std()));
  m.Add(12.5, 7.0, 0.5);  // ... until it leaves the window
  EXPECT_EQ(m.Count(), 1u);
  EXPECT_DOUBLE_EQ(m.Std(), 0.5);
}

TEST(TrailingMeanTest, TimeGoingBackStartsAfresh) {
  // A looping rosbag replay: the clock jumps back and old values must not mix with new ones.
  TrailingMean m(60.0);
  for (int i = 0; i < 10; ++i) m.Add(100.0 + i, 9.0, 0.1);
  m.Add(50.0, 2.0, 0.1);
  EXPECT_EQ(m.Count(), 1u);
  EXPECT_DOUBLE_EQ(m.Mean(), 2.0);
  EXPECT_DOUBLE_EQ(m.Oldest(), 50.0);
  EXPECT_EQ(m.Restarts(), 1u);
  m.Add(50.0, 3.0, 0.1);  // the same time again is not going back
  EXPECT_EQ(m.Restarts(), 1u);
  EXPECT_EQ(m.Count(), 2u);
}

// sdn_node's wind/estimate_mean starts at the first frame of the oldest clip averaged: the tag
// follows the window's oldest entry as entries leave it and when time goes back.
TEST(TrailingMeanTest, TheOldestTagFollowsTheWindow) {
  TrailingMean m(3.0);
  EXPECT_EQ(m.OldestTag(), 0u);
  // Stamps in nanoseconds beyond a double's 53 bits: they come back exactly.
  const std::uint64_t ns = 1'765'000'000'123'456'789ull;
  m.Add(10.0, 1.0, 0.1, ns);
  m.Add(11.0, 1.0, 0.1, ns + 1);
  EXPECT_EQ(m.OldestTag(), ns);
  m.Add(13.0, kNaN, kNaN, ns + 3);  // (10, 13]: the entry of t = 10 leaves
  EXPECT_EQ(m.OldestTag(), ns + 1);
  EXPECT_EQ(m.Count(), 1u);  // a non-finite value is an entry of the window, not of the mean
  m.Add(16.5, 2.0, 0.1, ns + 7);  // only the newest stays
  EXPECT_EQ(m.OldestTag(), ns + 7);
  m.Add(5.0, 2.0, 0.1, 42);  // time went back
  EXPECT_EQ(m.OldestTag(), 42u);
  EXPECT_EQ(m.Restarts(), 1u);
}

TEST(TrailingMeanTest, MatchesABruteForceMeanOverALongRandomStream) {
  // Many additions and removals: the running sums must agree with recomputing the window.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> dt(0.0, 2.5), v(0.0, 10.0), sd(0.1, 1.0);
  std::vector<double> ts, vs, ss;
  TrailingMean m(30.0);
  double t = 1e6;  // a large epoch time, as ROS stamps are
  for (int i = 0; i < 5000; ++i) {
    t += dt(rng);
    ts.push_back(t);
    vs.push_back(v(rng));
    ss.push_back(sd(rng));
    m.Add(ts.back(), vs.back(), ss.back());
    double sum = 0, var = 0;
    int n = 0;
    for (size_t j = 0; j < ts.size(); ++j) {
      if (ts[j] > t - 30.0) {
        sum += vs[j];
        var += ss[j] * ss[j];
        ++n;
      }
    }
    ASSERT_EQ(m.Count(), static_cast<size_t>(n)) << i;
    ASSERT_NEAR(m.Mean(), sum / n, 1e-9) << i;
    ASSERT_NEAR(m.Std(), std::sqrt(var / n), 1e-9) << i;
  }
}

// An outlier far above the rest must leave no trace once it has left the window (running sums
// lost the 4.0s added beside 1e17 for good).
TEST(TrailingMeanTest, AnOutlierLeavesNoTraceAfterItsWindow) {
  TrailingMean m(60.0);
  double t = 0.0;
  for (int i = 0; i < 100; ++i, t += 1.2) m.Add(t, 4.0, 0.3);
  m.Add(t, 1e17, 1e16);
  t += 1.2;
  for (int i = 0; i < 100; ++i, t += 1.2) m.Add(t, 4.0, 0.3);
  EXPECT_EQ(m.Mean(), 4.0);
  EXPECT_DOUBLE_EQ(m.Std(), 0.3);
}

}  // namespace
}  // namespace clothwind::sensors
