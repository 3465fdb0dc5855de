// The anemometer's bridge: a reading becomes a WindMeasurement in msg/WindMeasurement.msg's REP 103
// convention (velocity = speed * (cos, sin) of the direction), and a raw record survives the
// RawSentence round trip byte for byte, escapes included.
#include "ros_bridge/wind_conversions.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::ros_bridge {
namespace {

constexpr double kPi = 3.14159265358979323846;

sensors::WindReading Reading(double speed, double from_deg, sensors::AngleReference reference) {
  sensors::WindReading r;
  r.speed = speed;
  r.from_angle_deg = from_deg;
  r.reference = reference;
  r.source = reference == sensors::AngleReference::kInstrument ? "nmea_mwv" : "nmea_mwd";
  return r;
}

TEST(WindConversions, HeaderAndFieldsAreTheReadingsAndTheVelocityFollowsTheDirection) {
  sensors::WindReading r = Reading(5.0, 90.0, sensors::AngleReference::kInstrument);
  r.gust = 7.5;
  r.valid = false;
  r.relative = true;
  const ros::Time stamp(1700000000, 250000000);
  const WindMeasurement m = ToWindMeasurement(r, stamp, "anemometer");
  EXPECT_EQ(m.header.stamp, stamp);
  EXPECT_EQ(m.header.frame_id, "anemometer");
  EXPECT_EQ(m.speed, 5.0);
  EXPECT_EQ(m.gust, 7.5);
  EXPECT_FALSE(m.valid);
  EXPECT_TRUE(m.relative);
  EXPECT_EQ(m.source, "nmea_mwv");
  // From 90 deg clockwise of the mark (from starboard, the right): blows to the left, +y.
  EXPECT_NEAR(m.direction, kPi / 2, 1e-12);
  EXPECT_NEAR(m.velocity.x, 0.0, 1e-12);
  EXPECT_NEAR(m.velocity.y, 5.0, 1e-12);
  EXPECT_EQ(m.velocity.z, 0.0);
}

// Every direction: velocity is speed * (cos, sin) of it, and the angle is in (-pi, pi].
TEST(WindConversions, VelocityIsSpeedAlongTheDirectionForEveryAngleAndReference) {
  for (const auto reference : {sensors::AngleReference::kInstrument, sensors::AngleReference::kEarth}) {
    for (double from = 0.0; from < 360.0; from += 7.5) {
      const WindMeasurement m = ToWindMeasurement(Reading(3.0, from, reference), ros::Time(1, 0), "f");
      ASSERT_TRUE(std::isfinite(m.direction)) << from;
      EXPECT_GT(m.direction, -kPi - 1e-12) << from;
      EXPECT_LE(m.direction, kPi + 1e-12) << from;
      EXPECT_NEAR(m.velocity.x, 3.0 * std::cos(m.direction), 1e-9) << from;
      EXPECT_NEAR(m.velocity.y, 3.0 * std::sin(m.direction), 1e-9) << from;
    }
  }
  // A compass bearing in ENU: a westerly (from 270) blows east, +x; a northerly blows south, -y.
  EXPECT_NEAR(ToWindMeasurement(Reading(2.0, 270.0, sensors::AngleReference::kEarth), ros::Time(1, 0), "enu").velocity.x,
              2.0, 1e-9);
  EXPECT_NEAR(ToWindMeasurement(Reading(2.0, 0.0, sensors::AngleReference::kEarth), ros::Time(1, 0), "enu").velocity.y,
              -2.0, 1e-9);
}

// A magnetic bearing needs the declination: without it no direction (NaN), with it the true one.
TEST(WindConversions, AMagneticBearingTakesTheDeclination) {
  const sensors::WindReading r = Reading(4.0, 80.0, sensors::AngleReference::kMagnetic);
  EXPECT_TRUE(std::isnan(ToWindMeasurement(r, ros::Time(1, 0), "enu").direction));
  const WindMeasurement m = ToWindMeasurement(r, ros::Time(1, 0), "enu", 10.0);  // 10 deg east: true 90
  const WindMeasurement t = ToWindMeasurement(Reading(4.0, 90.0, sensors::AngleReference::kEarth), ros::Time(1, 0), "enu");
  EXPECT_NEAR(m.direction, t.direction, 1e-12);
}

// Real records: plain ASCII passes as it is; Gill's STX/ETX too; bytes outside ASCII and the
// backslash are escaped so rospy can decode the string, and come back whole.
TEST(WindConversions, RawRecordsRoundTripByteForByte) {
  const std::string nmea = "$IIMWV,045.0,R,5.2,M,A*3C";
  const RawSentence plain = ToRawSentence(nmea, "nmea", ros::Time(2, 0), "anemometer");
  EXPECT_EQ(plain.data, nmea);
  EXPECT_EQ(plain.protocol, "nmea");
  EXPECT_EQ(plain.header.frame_id, "anemometer");
  EXPECT_EQ(plain.header.stamp, ros::Time(2, 0));
  EXPECT_EQ(RawSentenceBytes(plain), nmea);
  const std::string gill = std::string("\x02") + "Q,229,002.74,M,00," + "\x03" + "06";
  EXPECT_EQ(ToRawSentence(gill, "gill", ros::Time(2, 0), "a").data, gill);
  std::string garbage = "a\\b";
  garbage += '\0';
  garbage += static_cast<char>(0xFF);
  garbage += static_cast<char>(0x80);
  const RawSentence escaped = ToRawSentence(garbage, "", ros::Time(2, 0), "a");
  EXPECT_EQ(escaped.data, "a\\x5Cb\\x00\\xFF\\x80");
  EXPECT_EQ(RawSentenceBytes(escaped), garbage);
  // Text that merely looks like an escape, written by the escaping itself, comes back as it was.
  const std::string literal = "\\x41";
  EXPECT_EQ(RawSentenceBytes(ToRawSentence(literal, "", ros::Time(2, 0), "a")), literal);
}

}  // namespace
}  // namespace clothwind::ros_bridge
