#include "sensors/reading_frames.h"

#include <string>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

WindReading Reading(const std::string& source, AngleReference reference) {
  WindReading r;
  r.speed = 3.0;
  r.source = source;
  r.reference = reference;
  r.from_angle_deg = reference == AngleReference::kNone ? kNaN : 90.0;
  return r;
}

TEST(ReadingFramesTest, BearingsGoInTheEarthFrameAndInstrumentAnglesInTheInstruments) {
  ReadingFrames frames("enu", "anemometer");
  EXPECT_EQ(frames.FrameFor(Reading("nmea_mwd", AngleReference::kEarth), "mast"), "enu");
  EXPECT_EQ(frames.FrameFor(Reading("nmea_mwd", AngleReference::kMagnetic), "mast"), "enu");
  EXPECT_EQ(frames.FrameFor(Reading("nmea_mwv", AngleReference::kInstrument), "mast"), "mast");
  EXPECT_EQ(frames.FrameFor(Reading("gill", AngleReference::kNone), "mast"), "mast");  // speed only
  // A station's calm reading has no bearing but goes with its type's others: in a frame that
  // flipped between the two, wind_display kept the first and dropped every later arrow.
  EXPECT_EQ(frames.FrameFor(Reading("fine_offset", AngleReference::kNone), "mast"), "enu");
  EXPECT_EQ(frames.FrameFor(Reading("nmea_mwd", AngleReference::kNone), "mast"), "enu");
  // Without an earth frame everything is in the instrument's.
  ReadingFrames none("", "anemometer");
  EXPECT_EQ(none.FrameFor(Reading("fine_offset", AngleReference::kEarth), "mast"), "mast");
}

TEST(ReadingFramesTest, WarnsOfBearingsInTheInstrumentsDefaultFrame) {
  ReadingFrames frames("", "anemometer");
  EXPECT_TRUE(frames.Warnings(true, "anemometer", false).empty());  // nothing seen yet
  frames.FrameFor(Reading("fine_offset", AngleReference::kEarth), "anemometer");
  auto w = frames.Warnings(true, "anemometer", false);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("compass bearings published in frame anemometer"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("set ~earth_frame_id or ~frame_id"), std::string::npos) << w[0];
  // A replay keeps the recorded frame: ~frame_id is not offered there.
  w = frames.Warnings(true, "anemometer", true);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].find("~frame_id"), std::string::npos) << w[0];
  // Bearings in a frame the user named are no warning.
  ReadingFrames named("", "anemometer");
  named.FrameFor(Reading("fine_offset", AngleReference::kEarth), "mast_enu");
  EXPECT_TRUE(named.Warnings(true, "mast_enu", false).empty());
}

TEST(ReadingFramesTest, WarnsOfBothKindsInOneFrameAndOfMagneticBearingsWithoutDeclination) {
  ReadingFrames frames("", "anemometer");
  frames.FrameFor(Reading("nmea_mwv", AngleReference::kInstrument), "mast");
  frames.FrameFor(Reading("nmea_mwd", AngleReference::kMagnetic), "mast");
  EXPECT_TRUE(frames.saw_instrument() && frames.saw_earth() && frames.saw_magnetic());
  auto w = frames.Warnings(false, "mast", false);
  ASSERT_EQ(w.size(), 2u);
  EXPECT_NE(w[0].find("set ~magnetic_declination"), std::string::npos) << w[0];
  EXPECT_NE(w[1].find("share frame mast"), std::string::npos) << w[1];
  EXPECT_EQ(frames.Warnings(true, "mast", false).size(), 1u);  // the declination known
  // With an earth frame set, the two kinds are apart.
  ReadingFrames apart("enu", "anemometer");
  apart.FrameFor(Reading("nmea_mwv", AngleReference::kInstrument), "mast");
  apart.FrameFor(Reading("nmea_mwd", AngleReference::kEarth), "mast");
  EXPECT_TRUE(apart.Warnings(true, "mast", false).empty());
}

}  // namespace
}  // namespace clothwind::sensors
