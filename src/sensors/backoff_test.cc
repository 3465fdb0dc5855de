#include "sensors/backoff.h"

#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

TEST(BackoffTest, DoublesUpToTheCeilingAndResets) {
  Backoff b(0.1, 2.0);
  EXPECT_DOUBLE_EQ(b.Next(), 0.1);
  EXPECT_DOUBLE_EQ(b.Next(), 0.2);
  EXPECT_DOUBLE_EQ(b.Next(), 0.4);
  EXPECT_DOUBLE_EQ(b.Next(), 0.8);
  EXPECT_DOUBLE_EQ(b.Next(), 1.6);
  EXPECT_DOUBLE_EQ(b.Next(), 2.0);  // not 3.2
  EXPECT_DOUBLE_EQ(b.Next(), 2.0);
  b.Reset();
  EXPECT_DOUBLE_EQ(b.Next(), 0.1);
  Backoff flat(1.0, 1.0);
  EXPECT_DOUBLE_EQ(flat.Next(), 1.0);
  EXPECT_DOUBLE_EQ(flat.Next(), 1.0);
}

TEST(BackoffTest, RefusesDelaysThatCannotBackOff) {
  EXPECT_THROW(Backoff(0.0, 1.0), std::invalid_argument);   // retries without pause
  EXPECT_THROW(Backoff(2.0, 1.0), std::invalid_argument);   // a ceiling below the start
  EXPECT_THROW(Backoff(0.1, std::numeric_limits<double>::infinity()), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sensors
