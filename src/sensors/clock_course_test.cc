#include "sensors/clock_course.h"

#include <limits>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

TEST(ClockCourseTest, AJumpBackRemembersWhereTheClockWasUntilItPassesItAgain) {
  ClockCourse c;
  EXPECT_FALSE(c.IsPreviousPass(100.0, 5.0));  // no jump yet: nothing is a previous pass
  for (int k = 0; k <= 2400; ++k) c.Note(1000.0 + k * 0.01);
  EXPECT_FALSE(c.IsPreviousPass(1020.0, 5.0));
  c.Note(1000.0);  // looped
  EXPECT_NEAR(c.before_last_jump(), 1024.0, 1e-9);
  EXPECT_TRUE(c.IsPreviousPass(1023.9, 5.0));
  EXPECT_TRUE(c.IsPreviousPass(1028.9, 5.0));
  EXPECT_FALSE(c.IsPreviousPass(1030.0, 5.0));  // past where it ever was: the future
  c.Note(1000.5);
  c.Note(1000.1);  // jitter under a second back is no jump (1000.5 forward of 1000.0 tested nothing)
  EXPECT_NEAR(c.before_last_jump(), 1024.0, 1e-9);
  c.Note(1024.5);  // past the old end: no previous pass pending
  EXPECT_FALSE(c.IsPreviousPass(1020.0, 5.0));
  c.Note(std::numeric_limits<double>::infinity());  // no clock: ignored
  EXPECT_DOUBLE_EQ(c.latest(), 1024.5);
}

}  // namespace
}  // namespace clothwind::sensors
