#include "sensors/reading_rate.h"

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

TEST(ReadingRateTest, ReadsTheRateBeforeAndAfterTheWindowFills) {
  ReadingRate rate;
  EXPECT_EQ(rate.Rate(100.0, 10.0), 0.0);  // no reading
  rate.Add(100.0);
  EXPECT_EQ(rate.Rate(100.5, 10.0), 0.0);  // one reading has no rate yet
  for (int i = 1; i <= 4; ++i) rate.Add(100.0 + 0.5 * i);  // 2 Hz
  EXPECT_DOUBLE_EQ(rate.Rate(102.0, 10.0), 2.0);  // 4 intervals over 2 s
  for (int i = 5; i <= 40; ++i) rate.Add(100.0 + 0.5 * i);
  EXPECT_DOUBLE_EQ(rate.Rate(120.1, 10.0), 2.0);  // 20 readings in [110.1, 120.1]
}

TEST(ReadingRateTest, ASilentInstrumentReadsSlowerAsItsReadingsAgeOut) {
  ReadingRate rate;
  for (int i = 0; i <= 40; ++i) rate.Add(100.0 + 0.5 * i);  // 2 Hz up to t = 120
  EXPECT_DOUBLE_EQ(rate.Rate(120.1, 10.0), 2.0);
  EXPECT_DOUBLE_EQ(rate.Rate(125.1, 10.0), 1.0);  // 10 readings left in [115.1, 125.1]
  EXPECT_EQ(rate.Rate(131.0, 10.0), 0.0);
  rate.Add(131.5);  // back: the rate over the window, not over the new reading alone
  EXPECT_DOUBLE_EQ(rate.Rate(132.0, 10.0), 0.1);
}

TEST(ReadingRateTest, TheClockGoingBackStartsAfresh) {
  ReadingRate rate;
  for (int i = 0; i <= 40; ++i) rate.Add(1000.0 + 0.5 * i);
  // A looped replay: the clock is back at 10 and the readings come at 1 Hz.
  for (int i = 0; i <= 4; ++i) rate.Add(10.0 + i);
  EXPECT_DOUBLE_EQ(rate.Rate(14.0, 10.0), 1.0);  // 4 intervals over 4 s, none of the old pass's
}

TEST(ReadingRateTest, TheClockGoingBackLessThanItsRunStartsAfreshToo) {
  // The clock back to a time after the first reading (a /clock glitch, or a loop whose pass
  // starts later than the first one did): the first time was kept, and the new pass's 1 Hz read
  // as 1 reading over 6 s.
  ReadingRate rate;
  for (int i = 0; i <= 10; ++i) rate.Add(10.0 + i);
  rate.Add(15.0);
  rate.Add(16.0);
  EXPECT_DOUBLE_EQ(rate.Rate(16.0, 60.0), 1.0);  // 1 interval over the 1 s since 15
}

TEST(ReadingRateTest, AReadingAtTimeZeroIsNoFirstTime) {
  // Topic input on a replay's clock: a record before /clock is stamped 0, and the diagnostics at
  // 1000 forget it; the rate from the readings at 2 Hz since 1000.5 is not read over 1003 s.
  ReadingRate rate;
  rate.Add(0.0);
  EXPECT_EQ(rate.Rate(1000.0, 10.0), 0.0);
  for (int i = 1; i <= 5; ++i) rate.Add(1000.0 + 0.5 * i);
  EXPECT_DOUBLE_EQ(rate.Rate(1003.0, 10.0), 1.6);  // 4 intervals over the 2.5 s since 1000.5
}

TEST(ReadingRateTest, KeepsAtMostItsLimit) {
  ReadingRate rate(/*max_kept=*/5);
  for (int i = 0; i < 100; ++i) rate.Add(100.0 + 0.01 * i);
  EXPECT_DOUBLE_EQ(rate.Rate(120.0, 10.0), 0.0);
  for (int i = 0; i < 100; ++i) rate.Add(120.0 + 0.01 * i);
  EXPECT_DOUBLE_EQ(rate.Rate(121.0, 10.0), 0.5);  // the 5 kept over the filled window
}

}  // namespace
}  // namespace clothwind::sensors
