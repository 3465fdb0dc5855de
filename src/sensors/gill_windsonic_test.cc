#include "sensors/gill_windsonic.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

// The polar example printed in the WindSonic manual (doc 1405 PS 0019, section 9.1), checksum 16.
const std::string kManualPolar = std::string("\x02") + "Q,229,002.74,M,00," + "\x03" + "16";

TEST(GillWindSonic, ManualPolarExample) {
  EXPECT_EQ(GillChecksum("Q,229,002.74,M,00,"), 0x16);
  const ParseResult r = ParseGillWindSonic(kManualPolar);
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 2.74);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 229.0);
  EXPECT_EQ(r.reading.reference, AngleReference::kInstrument);
  EXPECT_TRUE(r.reading.valid);
  EXPECT_EQ(r.reading.source, "gill");
  EXPECT_EQ(FrameGillRecord("Q,229,002.74,M,00,"), kManualPolar);
}

TEST(GillWindSonic, BadChecksumAndTruncation) {
  std::string bad = kManualPolar;
  bad.back() = '7';
  EXPECT_EQ(ParseGillWindSonic(bad).status, ParseStatus::kChecksumError);
  std::string flipped = kManualPolar;
  flipped[3] = '3';  // 229 -> 329, checksum no longer matches
  EXPECT_EQ(ParseGillWindSonic(flipped).status, ParseStatus::kChecksumError);
  EXPECT_EQ(ParseGillWindSonic(kManualPolar.substr(0, 12)).status, ParseStatus::kMalformed);  // no ETX
  EXPECT_EQ(ParseGillWindSonic(kManualPolar.substr(0, kManualPolar.size() - 1)).status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseGillWindSonic("Q,229,002.74,M,00,").status, ParseStatus::kMalformed);  // no STX
  EXPECT_EQ(ParseGillWindSonic(std::string("\x02\x03") + "00").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseGillWindSonic(std::string("\x02\xff\xfe\x03") + "01").status, ParseStatus::kMalformed);
}

TEST(GillWindSonic, UnitsAndUnknownUnits) {
  ParseResult r = ParseGillWindSonic(FrameGillRecord("Q,010,010.00,N,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 5.14444, 1e-5);
  r = ParseGillWindSonic(FrameGillRecord("Q,010,036.00,K,00,"));
  EXPECT_NEAR(r.reading.speed, 10.0, 1e-9);
  r = ParseGillWindSonic(FrameGillRecord("Q,010,010.00,P,00,"));
  EXPECT_NEAR(r.reading.speed, 4.4704, 1e-9);
  r = ParseGillWindSonic(FrameGillRecord("Q,010,500.00,F,00,"));
  EXPECT_NEAR(r.reading.speed, 2.54, 1e-9);
  r = ParseGillWindSonic(FrameGillRecord("Q,010,010.00,S,00,"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("units"), std::string::npos);
}

TEST(GillWindSonic, StatusCodes) {
  ParseResult r = ParseGillWindSonic(FrameGillRecord("Q,229,002.74,M,01,"));
  ASSERT_EQ(r.status, ParseStatus::kOk);
  EXPECT_FALSE(r.reading.valid);
  EXPECT_NE(r.reading.status.find("axis 1"), std::string::npos);
  r = ParseGillWindSonic(FrameGillRecord("Q,,,M,04,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  // Fixed-field mode pads a failed measurement with 9s: a void reading, not a malformed record.
  r = ParseGillWindSonic(FrameGillRecord("Q,999,999.99,M,04,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  EXPECT_NE(r.reading.status.find("04"), std::string::npos);
  EXPECT_TRUE(std::isnan(r.reading.speed));
  r = ParseGillWindSonic(FrameGillRecord("Q,229,002.74,M,0A,"));
  EXPECT_FALSE(r.reading.valid);
  r = ParseGillWindSonic(FrameGillRecord("Q,229,002.74,M,51,"));
  EXPECT_TRUE(r.reading.valid);
  r = ParseGillWindSonic(FrameGillRecord("Q,229,002.74,M,60,"));
  EXPECT_TRUE(r.reading.valid);
  bool ok = true;
  GillStatusText("77", &ok);
  EXPECT_FALSE(ok);
}

TEST(GillWindSonic, CalmAirHasNoDirection) {
  ParseResult r = ParseGillWindSonic(FrameGillRecord("Q,,000.03,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 0.03);
  EXPECT_TRUE(std::isnan(WindDirection(r.reading)));
  // Fixed-field mode freezes the last direction below 0.05 m/s (the manual's own example, 9.1):
  // a speed, no direction.
  r = ParseGillWindSonic(FrameGillRecord("Q,133,000.02,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 0.02);
  EXPECT_EQ(r.reading.reference, AngleReference::kNone);
  EXPECT_TRUE(std::isnan(WindDirection(r.reading)));
  // A UV pair that small points anywhere.
  r = ParseGillWindSonic(FrameGillRecord("Q,+000.01,-000.01,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 0.0141, 1e-4);
  EXPECT_EQ(r.reading.reference, AngleReference::kNone);
  // From 0.05 m/s on, the direction is the instrument's.
  r = ParseGillWindSonic(FrameGillRecord("Q,133,000.05,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 133.0);
}

TEST(GillWindSonic, AWindObserverTunnelRecordIsNotReadAsPolar) {
  // WindObserver II tunnel mode: speed 1.59, polarity 1. Read as polar it was 1 m/s from 1.59 deg.
  const ParseResult r = ParseGillWindSonic(FrameGillRecord("A,001.59,1,M,00,"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 2 (direction): expected whole degrees 0..360, got '001.59'"), std::string::npos)
      << r.error;
}

TEST(GillWindSonic, UvAgreesWithPolar) {
  // Wind from the instrument's east side (90 deg): air moves towards the west side, +V
  // (manual 9.2: V is the "East - West" axis, as U is "South - North").
  ParseResult r = ParseGillWindSonic(FrameGillRecord("Q,+000.00,+002.00,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.from_angle_deg, 90.0, 1e-9);
  EXPECT_NEAR(r.reading.speed, 2.0, 1e-12);
  // "+U vector is a wind from the South direction" (manual 9.6): from 180 deg.
  r = ParseGillWindSonic(FrameGillRecord("Q,+002.00,+000.00,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.from_angle_deg, 180.0, 1e-9);
  // Every polar angle: UV components of the same wind give the same reading.
  for (int from = 0; from < 360; from += 15) {
    const double s = 3.0, d = DirectionFromInstrumentAngle(from);
    char body[64];
    std::snprintf(body, sizeof(body), "Q,%+07.2f,%+07.2f,M,00,", s * std::cos(d), s * std::sin(d));
    r = ParseGillWindSonic(FrameGillRecord(body));
    ASSERT_EQ(r.status, ParseStatus::kOk) << body << " " << r.error;
    EXPECT_NEAR(r.reading.speed, s, 0.01) << body;
    EXPECT_NEAR(std::cos(WindDirection(r.reading)), std::cos(d), 0.01) << body;
    EXPECT_NEAR(std::sin(WindDirection(r.reading)), std::sin(d), 0.01) << body;
  }
  // The UV layout as printed in the manual (its printed checksum belongs to another example).
  r = ParseGillWindSonic(FrameGillRecord("Q,+001.59,-002.74,M,00,"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, std::hypot(1.59, 2.74), 1e-9);
  const auto v = WindVelocity(r.reading);
  EXPECT_NEAR(v[0], 1.59, 1e-9);
  EXPECT_NEAR(v[1], -2.74, 1e-9);
  // A UV record that lost a component is malformed, named, not a polar reading without direction.
  for (const auto& [body, field] : {std::pair<std::string, std::string>{"Q,,+002.00,M,00,", "field 2 (U)"},
                                    {"Q,+002.00,,M,00,", "field 3 (V)"}}) {
    r = ParseGillWindSonic(FrameGillRecord(body));
    EXPECT_EQ(r.status, ParseStatus::kMalformed) << body;
    EXPECT_NE(r.error.find(field), std::string::npos) << r.error;
  }
  // A polar direction beside a negative speed: the speed refused, not read as U = 45, V = -2.
  r = ParseGillWindSonic(FrameGillRecord("Q,045,-002.00,M,00,"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 3 (speed): expected >= 0, got '-002.00'"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace clothwind::sensors
