#include "sensors/display_clock.h"

#include <cstdint>
#include <stdexcept>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

using Verdict = DisplayClock::Verdict;

constexpr int kEstimate = 0, kWind = 1;
// Seconds of ROS time as nanoseconds.
constexpr std::uint64_t S(double s) { return static_cast<std::uint64_t>(s * 1e9); }

DisplayClock Clock() { return DisplayClock(2, /*max_future=*/5.0, /*restart_after=*/5.0); }

TEST(DisplayClockTest, ShowsStampedInputsAndKeepsEachInputsNewestExactly) {
  DisplayClock clock = Clock();
  bool restarted = true;
  const std::uint64_t stamp = 1'765'000'000'123'456'789ull;  // beyond a double's 53 bits
  EXPECT_EQ(clock.Admit(kWind, stamp, stamp + S(0.1), &restarted), Verdict::kShow);
  EXPECT_FALSE(restarted);
  EXPECT_EQ(clock.Newest(kWind), stamp);
  EXPECT_EQ(clock.Newest(kEstimate), 0u);
  // An estimate 6 s behind the newest reading, past restart_after, is neither late nor a restart:
  // inputs are judged by their own newest (2 s behind, within restart_after, could not tell).
  EXPECT_EQ(clock.Admit(kEstimate, stamp - S(6), stamp + S(0.2), &restarted), Verdict::kShow);
  EXPECT_FALSE(restarted);
  // An older reading within restart_after joins the history but does not move the newest back.
  EXPECT_EQ(clock.Admit(kWind, stamp - S(1), stamp + S(0.3), &restarted), Verdict::kShow);
  EXPECT_EQ(clock.Newest(kWind), stamp);
  EXPECT_EQ(clock.Restarts(), 0u);
}

TEST(DisplayClockTest, RefusesUnstampedAndFutureStampsOfARunningClock) {
  DisplayClock clock = Clock();
  bool restarted = false;
  EXPECT_EQ(clock.Admit(kWind, 0, S(100), &restarted), Verdict::kUnstamped);
  EXPECT_EQ(clock.Admit(kWind, S(105.5), S(100), &restarted), Verdict::kFuture);
  EXPECT_EQ(clock.Admit(kWind, S(104.9), S(100), &restarted), Verdict::kShow);  // within max_future
  // Exactly max_future ahead is shown, as ros::Time's seconds compare (15e9 * 1e-9 rounds above 15).
  DisplayClock early = Clock();
  EXPECT_EQ(early.Admit(kWind, 15'000'000'000ull, 10'000'000'000ull, &restarted), Verdict::kShow);
  // TIME_MAX (2^32 - 1 s): refused, and nothing overflows.
  EXPECT_EQ(clock.Admit(kEstimate, 4294967295ull * 1000000000ull + 999999999ull, S(100), &restarted),
            Verdict::kFuture);
  // Before the clock starts, no stamp is "in the future".
  DisplayClock unclocked = Clock();
  EXPECT_EQ(unclocked.Admit(kWind, S(1e6), 0, &restarted), Verdict::kShow);
  EXPECT_EQ(clock.Restarts(), 0u);
}

TEST(DisplayClockTest, TheClockGoingBackRestartsOnceAndTheOldPassesTailIsDropped) {
  DisplayClock clock = Clock();
  bool restarted = false;
  clock.CheckClock(S(200));
  clock.Admit(kWind, S(199.5), S(200), &restarted);
  clock.Admit(kEstimate, S(198), S(200), &restarted);
  // The bag is played again: the clock is back at 100.
  EXPECT_TRUE(clock.CheckClock(S(100)));
  EXPECT_EQ(clock.Restarts(), 1u);
  EXPECT_EQ(clock.Newest(kWind), 0u);
  EXPECT_FALSE(clock.CheckClock(S(100.5)));  // once
  // sdn_node's queue still holds an estimate of the previous pass: not a clock fault.
  EXPECT_EQ(clock.Admit(kEstimate, S(199), S(100.5), &restarted), Verdict::kPreviousPass);
  EXPECT_FALSE(restarted);
  // Beyond the previous pass's end it is the future again.
  EXPECT_EQ(clock.Admit(kEstimate, S(206), S(100.5), &restarted), Verdict::kFuture);
  EXPECT_EQ(clock.Admit(kWind, S(100.4), S(100.5), &restarted), Verdict::kShow);
  EXPECT_EQ(clock.Restarts(), 1u);
}

TEST(DisplayClockTest, TheFirstMessageOfANewPassRestartsBeforeTheTickDoes) {
  DisplayClock clock = Clock();
  bool restarted = false;
  clock.Admit(kWind, S(300), S(300), &restarted);
  // The new pass's first estimate: its own input has no newest yet, so only the clock says so.
  EXPECT_EQ(clock.Admit(kEstimate, S(50), S(50), &restarted), Verdict::kShow);
  EXPECT_TRUE(restarted);
  EXPECT_EQ(clock.Newest(kWind), 0u);  // the previous pass's reading is forgotten
  EXPECT_EQ(clock.Newest(kEstimate), S(50));
  EXPECT_FALSE(clock.CheckClock(S(50.5)));  // the tick after it does not restart again
  EXPECT_EQ(clock.Restarts(), 1u);
}

TEST(DisplayClockTest, ALateMessageIsDroppedWhileTheClockRunsOnAndRestartsWithoutAClock) {
  DisplayClock clock = Clock();
  bool restarted = false;
  clock.Admit(kWind, S(500), S(500), &restarted);
  // 6 s behind the newest reading while the clock is at 500.2: a stray, not a restart.
  EXPECT_EQ(clock.Admit(kWind, S(494), S(500.2), &restarted), Verdict::kLate);
  EXPECT_FALSE(restarted);
  EXPECT_EQ(clock.Newest(kWind), S(500));
  // With no clock, an input going back is the only sign of a replay restarting.
  DisplayClock unclocked = Clock();
  unclocked.Admit(kWind, S(500), 0, &restarted);
  EXPECT_EQ(unclocked.Admit(kWind, S(10), 0, &restarted), Verdict::kShow);
  EXPECT_TRUE(restarted);
  EXPECT_EQ(unclocked.Newest(kWind), S(10));
  EXPECT_EQ(unclocked.Restarts(), 1u);
}

TEST(DisplayClockTest, TheDisplaysNowIsTheClockButNeverBeforeTheNewestInput) {
  DisplayClock clock = Clock();
  bool restarted = false;
  EXPECT_EQ(clock.DisplayNow(0), 0u);  // neither a clock nor an input
  EXPECT_EQ(clock.DisplayNow(S(10)), S(10));
  clock.Admit(kWind, S(12), S(10), &restarted);
  EXPECT_EQ(clock.DisplayNow(S(10)), S(12));  // an input ahead of the clock (latency, skew)
  EXPECT_EQ(clock.DisplayNow(S(20)), S(20));  // the plot scrolls while inputs pause
  EXPECT_EQ(clock.DisplayNow(0), S(12));
  // The clock more than restart_after behind the newest (a replay restarting, not yet noticed):
  // the newest input, not a time far in the display's past.
  EXPECT_EQ(clock.DisplayNow(S(5)), S(12));
}

TEST(DisplayClockTest, RefusesBadSettings) {
  EXPECT_THROW(DisplayClock(0, 5.0, 5.0), std::invalid_argument);
  EXPECT_THROW(DisplayClock(1, 0.0, 5.0), std::invalid_argument);
  EXPECT_THROW(DisplayClock(1, 5.0, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sensors
