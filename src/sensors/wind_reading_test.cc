#include "sensors/wind_reading.h"

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

TEST(WindReading, SpeedUnitsConvertToMetresPerSecond) {
  EXPECT_NEAR(SpeedToMetresPerSecond(1.0, SpeedUnit::kKnots), 0.514444, 1e-6);
  EXPECT_NEAR(SpeedToMetresPerSecond(3.6, SpeedUnit::kKilometresPerHour), 1.0, 1e-12);
  EXPECT_NEAR(SpeedToMetresPerSecond(1.0, SpeedUnit::kMilesPerHour), 0.44704, 1e-9);
  EXPECT_NEAR(SpeedToMetresPerSecond(100.0, SpeedUnit::kFeetPerMinute), 0.508, 1e-9);
  EXPECT_DOUBLE_EQ(SpeedToMetresPerSecond(7.25, SpeedUnit::kMetresPerSecond), 7.25);
}

TEST(WindReading, WrapAngleLandsInHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(WrapAngle(M_PI), M_PI);
  EXPECT_DOUBLE_EQ(WrapAngle(-M_PI), M_PI);
  EXPECT_NEAR(WrapAngle(3 * M_PI), M_PI, 1e-12);
  EXPECT_NEAR(WrapAngle(2 * M_PI + 0.25), 0.25, 1e-12);
  for (double a = -20.0; a < 20.0; a += 0.173) {
    const double w = WrapAngle(a);
    EXPECT_GT(w, -M_PI);
    EXPECT_LE(w, M_PI);
    EXPECT_NEAR(std::cos(w), std::cos(a), 1e-12);
    EXPECT_NEAR(std::sin(w), std::sin(a), 1e-12);
  }
  EXPECT_TRUE(std::isnan(WrapAngle(kNaN)));
}

TEST(WindReading, InstrumentAnglesFollowRep103) {
  // From ahead (0 deg): air moves backwards, towards -x.
  EXPECT_NEAR(std::fabs(DirectionFromInstrumentAngle(0.0)), M_PI, 1e-12);
  // From the right (90 deg clockwise = -y side): air moves towards +y (left).
  EXPECT_NEAR(DirectionFromInstrumentAngle(90.0), M_PI / 2, 1e-12);
  // From behind: towards +x.
  EXPECT_NEAR(DirectionFromInstrumentAngle(180.0), 0.0, 1e-12);
  EXPECT_NEAR(DirectionFromInstrumentAngle(270.0), -M_PI / 2, 1e-12);
}

TEST(WindReading, CompassBearingsMapToEnu) {
  EXPECT_NEAR(DirectionFromBearing(0.0), -M_PI / 2, 1e-12);   // northerly blows south
  EXPECT_NEAR(DirectionFromBearing(270.0), 0.0, 1e-12);       // westerly blows east
  EXPECT_NEAR(DirectionFromBearing(180.0), M_PI / 2, 1e-12);  // southerly blows north
  EXPECT_NEAR(std::fabs(DirectionFromBearing(90.0)), M_PI, 1e-12);
}

TEST(WindReading, VelocityPointsAwayFromWhereTheWindComesFrom) {
  for (double from = 0.0; from < 360.0; from += 7.5) {
    WindReading r;
    r.speed = 3.0;
    r.from_angle_deg = from;
    r.reference = AngleReference::kInstrument;
    const auto v = WindVelocity(r);
    // Unit vector towards the source, clockwise `from` from +x in a y-left frame.
    const double sx = std::cos(from * M_PI / 180.0), sy = -std::sin(from * M_PI / 180.0);
    EXPECT_NEAR(v[0] * sx + v[1] * sy, -3.0, 1e-9) << from;
    EXPECT_NEAR(std::hypot(v[0], v[1]), 3.0, 1e-9);
    EXPECT_EQ(v[2], 0.0);
  }
}

TEST(WindReading, VelocityWithoutDirection) {
  WindReading calm;
  calm.speed = 0.0;
  const auto z = WindVelocity(calm);
  EXPECT_EQ(z[0], 0.0);
  EXPECT_EQ(z[1], 0.0);
  WindReading blind;
  blind.speed = 2.0;
  EXPECT_TRUE(std::isnan(WindVelocity(blind)[0]));
  EXPECT_TRUE(std::isnan(WindDirection(blind)));
}

}  // namespace
}  // namespace clothwind::sensors
