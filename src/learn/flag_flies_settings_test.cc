// sdn_node's ~flag_flies settings in every combination the node's rostest does not reach.
#include "learn/flag_flies_settings.h"

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::learn {
namespace {

// Whether `s` names one error containing `part`.
bool Names(const FlagFliesSettings& s, const std::string& part) {
  for (const std::string& e : s.errors)
    if (e.find(part) != std::string::npos) return true;
  return false;
}

TEST(FlagFliesSettings, WindFollowsTheHeadingGivenOrThePoseInTf) {
  FlagFliesSettings s = ReadFlagFliesSettings("wind", 1.5, "", 20);
  EXPECT_TRUE(s.follow_wind);
  EXPECT_FALSE(s.pose_from_tf);
  EXPECT_DOUBLE_EQ(s.camera_heading, 1.5);
  EXPECT_TRUE(s.errors.empty());
  s = ReadFlagFliesSettings("wind", std::nullopt, "", 20);
  EXPECT_TRUE(s.follow_wind);
  EXPECT_TRUE(s.pose_from_tf);
  EXPECT_TRUE(s.errors.empty());
  EXPECT_FALSE(s.told);
}

TEST(FlagFliesSettings, AHeadingThatIsNoAngleIsNotFollowed) {
  for (const double bad : {std::nan(""), std::numeric_limits<double>::infinity(), 90.0}) {
    const FlagFliesSettings s = ReadFlagFliesSettings("wind", bad, "", 20);
    EXPECT_FALSE(s.follow_wind) << bad;
    EXPECT_FALSE(s.pose_from_tf) << bad;  // a bad heading is not replaced by tf silently
    EXPECT_TRUE(Names(s, "~flag_flies wind is not followed")) << bad;
  }
  EXPECT_TRUE(Names(ReadFlagFliesSettings("wind", 90.0, "", 20), "beyond 2 pi: it is in radians (degrees given?)"));
}

TEST(FlagFliesSettings, ParametersReadButUnusedAreNamed) {
  // A heading frame without a heading, under tf: the frame is the clip's own.
  EXPECT_TRUE(Names(ReadFlagFliesSettings("wind", std::nullopt, "enu", 20),
                    "~camera_heading_frame is set without ~camera_heading"));
  // With a heading the frame is used: no error.
  EXPECT_TRUE(ReadFlagFliesSettings("wind", 0.5, "enu", 20).errors.empty());
  // A heading without wind.
  const FlagFliesSettings s = ReadFlagFliesSettings("right", 1.0, "", 20);
  EXPECT_TRUE(Names(s, "~camera_heading is set but ~flag_flies is 'right', not wind"));
  EXPECT_EQ(s.told, FlagFlies::kRight);
  EXPECT_FALSE(s.follow_wind);
  EXPECT_TRUE(Names(ReadFlagFliesSettings("", std::nan(""), "", 20), "~camera_heading is not a finite angle [rad]; it is ignored"));
}

TEST(FlagFliesSettings, OutOfRangeValuesLeaveTheirDefaults) {
  FlagFliesSettings s = ReadFlagFliesSettings("sideways", std::nullopt, "", 120);
  EXPECT_FALSE(s.told);  // the model's own way
  EXPECT_TRUE(Names(s, "(or wind); the model's way is used"));
  EXPECT_TRUE(Names(s, "~end_on_angle must be 0 to 90 degrees, got 120"));
  EXPECT_DOUBLE_EQ(s.end_on, 20.0 * M_PI / 180.0);
  s = ReadFlagFliesSettings("left", std::nullopt, "", 35);
  EXPECT_EQ(s.told, FlagFlies::kLeft);
  EXPECT_DOUBLE_EQ(s.end_on, 35.0 * M_PI / 180.0);
  EXPECT_TRUE(s.errors.empty());
  EXPECT_FALSE(ReadFlagFliesSettings("", std::nullopt, "", 20).told);
}

}  // namespace
}  // namespace clothwind::learn
