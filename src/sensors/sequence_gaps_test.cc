#include "sensors/sequence_gaps.h"

#include <cstdint>
#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

TEST(SequenceGapsTest, CountsTheNumbersSkippedBetweenGoodItems) {
  SequenceGaps gaps;
  EXPECT_EQ(gaps.Good(5, 0.0), 0u);  // the first item: nothing before it is known
  EXPECT_EQ(gaps.Good(6, 1.0), 0u);
  EXPECT_EQ(gaps.Good(9, 2.0), 2u);  // 7 and 8
  EXPECT_EQ(gaps.Good(10, 3.0), 0u);
  EXPECT_EQ(gaps.Good(14, 4.0), 3u);
  EXPECT_EQ(gaps.Missing(), 5u);
}

TEST(SequenceGapsTest, MalformedItemsArrivedAndDoNotMoveTheSequence) {
  SequenceGaps gaps;
  gaps.Good(1, 0.0);
  gaps.Malformed(1000);  // a stray number: not 998 missing when 2 comes
  EXPECT_EQ(gaps.Good(2, 1.0), 0u);
  gaps.Malformed(3);  // 3 and 4 came, malformed; 5 did not come at all
  gaps.Malformed(4);
  EXPECT_EQ(gaps.Good(6, 2.0), 1u);
  // Malformed numbers are forgotten at the next good item: 7 below is missing, whatever came before.
  gaps.Malformed(7);
  gaps.Good(6, 2.5);  // a repeat of 6 (below: a restart) clears them
  EXPECT_EQ(gaps.Good(8, 3.0), 1u);
  EXPECT_EQ(gaps.Missing(), 2u);
}

TEST(SequenceGapsTest, ARestartOrANewNumberingIsNotALoss) {
  SequenceGaps gaps(/*max_gap=*/100);
  gaps.Good(50, 0.0);
  EXPECT_EQ(gaps.Good(3, 1.0), 0u);   // a restarted buffer numbers from the start
  EXPECT_EQ(gaps.Good(5, 2.0), 1u);   // and is counted from there
  EXPECT_EQ(gaps.Good(106, 3.0), 100u);  // the largest jump read as losses
  EXPECT_EQ(gaps.Good(208, 4.0), 0u);    // one more is a new numbering
  SequenceGaps wide;
  const std::uint64_t top = std::uint64_t{1} << 63;
  wide.Good(top, 0.0);
  EXPECT_EQ(wide.Good(0, 1.0), 0u);
  wide.Good(std::numeric_limits<std::uint64_t>::max() - 1, 2.0);  // no overflow past the top
  EXPECT_EQ(wide.Good(std::numeric_limits<std::uint64_t>::max(), 3.0), 0u);
  EXPECT_EQ(wide.Good(5, 4.0), 0u);  // after the top number: a restart (last + 1 wraps to 0)
  EXPECT_EQ(wide.Missing(), 0u);
}

TEST(SequenceGapsTest, RecentMissingForgetsGapsOlderThanItsWindow) {
  SequenceGaps gaps(25ull * 86400, 30.0);
  gaps.Good(0, 100.0);
  gaps.Good(3, 101.0);  // 2 missing at 101
  gaps.Good(5, 120.0);  // 1 missing at 120
  EXPECT_EQ(gaps.RecentMissing(125.0), 3u);
  EXPECT_EQ(gaps.RecentMissing(131.5), 1u);  // the gap at 101 is over 30 s old
  EXPECT_EQ(gaps.RecentMissing(150.0), 1u);  // [120, 150]: closed at its start, as sdn_node's rate
  EXPECT_EQ(gaps.RecentMissing(150.5), 0u);
  EXPECT_EQ(gaps.Missing(), 3u);             // the total keeps them
  EXPECT_THROW(SequenceGaps(10, 0.0), std::invalid_argument);
}

TEST(SequenceGapsTest, TheMalformedItemsRememberedAreBounded) {
  SequenceGaps gaps;
  gaps.Good(0, 0.0);
  const std::uint64_t n = SequenceGaps::kMaxMalformed + 10;
  for (std::uint64_t i = 1; i <= n; ++i) gaps.Malformed(i);
  // The first kMaxMalformed are remembered; the 10 beyond them read as missing.
  EXPECT_EQ(gaps.Good(n + 1, 1.0), 10u);
}

}  // namespace
}  // namespace clothwind::sensors
