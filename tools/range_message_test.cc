#include "range_message.h"

#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {

// The text CLI11's Range validator makes (std::to_string of its bounds).
std::string Cli11Range(const std::string& value, double low, double high) {
  return "--clips: Value " + value + " not in range " + std::to_string(low) + " to " + std::to_string(high);
}

TEST(ReadableRangeMessage, SaysAnUnboundedRangeAsABound) {
  const double max = std::numeric_limits<double>::max();
  EXPECT_EQ(ReadableRangeMessage(Cli11Range("-1", 0, max), false), "--clips: Value -1 must be >= 0");
  // A positive-number check: its bound, the smallest double, prints as 0.000000 like the one above.
  for (const std::string value : {"0", "-3"})
    EXPECT_EQ(ReadableRangeMessage(Cli11Range(value, std::numeric_limits<double>::min(), max), true),
              "--clips: Value " + value + " must be > 0");
  EXPECT_EQ(ReadableRangeMessage(Cli11Range("0.5", 1, max), false), "--clips: Value 0.5 must be >= 1");
}

TEST(ReadableRangeMessage, TrimsABoundedRangeAndLeavesOtherMessages) {
  EXPECT_EQ(ReadableRangeMessage(Cli11Range("7", 1, 5), false), "--clips: Value 7 not in range 1 to 5");
  EXPECT_EQ(ReadableRangeMessage(Cli11Range("1.5", 0, 1), false), "--clips: Value 1.5 not in range 0 to 1");
  EXPECT_EQ(ReadableRangeMessage("--seed: expected a whole number", false), "--seed: expected a whole number");
  EXPECT_EQ(TrimmedNumber("2.500000"), "2.5");
  EXPECT_EQ(TrimmedNumber("10"), "10");
}

}  // namespace
}  // namespace clothwind::tools
