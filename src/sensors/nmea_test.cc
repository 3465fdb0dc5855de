#include "sensors/nmea.h"

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

constexpr double kKnot = 1852.0 / 3600.0;

TEST(Nmea, ChecksumMatchesThePublishedGgaExample) {
  // The classic NMEA 0183 GGA example sentence, checksum 47 as published.
  NmeaSentence s;
  ParseResult err;
  ASSERT_TRUE(SplitNmeaSentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47", &s, &err))
      << err.error;
  EXPECT_EQ(s.talker, "GP");
  EXPECT_EQ(s.type, "GGA");
  EXPECT_EQ(s.fields.size(), 14u);
  EXPECT_EQ(ParseNmea("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47").status,
            ParseStatus::kNotWind);
}

TEST(Nmea, MwvRelativeKnots) {
  const ParseResult r = ParseNmea("$IIMWV,229.0,R,5.8,N,A*39");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 5.8 * kKnot, 1e-9);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 229.0);
  EXPECT_EQ(r.reading.reference, AngleReference::kInstrument);
  EXPECT_TRUE(r.reading.relative);
  EXPECT_TRUE(r.reading.valid);
  EXPECT_EQ(r.reading.source, "nmea_mwv");
  EXPECT_NEAR(WindDirection(r.reading), WrapAngle(M_PI - 229.0 * M_PI / 180), 1e-12);
}

TEST(Nmea, MwvUnits) {
  ParseResult r = ParseNmea("$WIMWV,045.0,T,12.6,M,A*12");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 12.6);
  EXPECT_FALSE(r.reading.relative);
  r = ParseNmea("$IIMWV,090.0,R,36.0,K,A*04");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 10.0, 1e-12);
  r = ParseNmea("$IIMWV,180.0,T,10.0,S,A*1E");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 4.4704, 1e-9);
  // A Gill WindSonic in NMEA mode writes its own unit letters: P (mph), F (ft/min).
  r = ParseNmea(WithNmeaChecksum("IIMWV,120,R,004.70,P,A"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 4.70 * 0.44704, 1e-9);
  r = ParseNmea(WithNmeaChecksum("IIMWV,120,R,0500,F,A"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 500 * 0.00508, 1e-9);
  r = ParseNmea(WithNmeaChecksum("IIMWV,120,R,004.70,Q,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("expected K, M, N or S (or Gill's P, F), got 'Q'"), std::string::npos) << r.error;
  // Lower-case checksum digits are accepted; a missing checksum too.
  EXPECT_EQ(ParseNmea("$IIMWV,180.0,T,10.0,S,A*1e").status, ParseStatus::kOk);
  EXPECT_EQ(ParseNmea("$IIMWV,180.0,T,10.0,S,A").status, ParseStatus::kOk);
}

TEST(Nmea, MwvVoidWithEveryFieldEmptyIsAnInvalidReadingNotAMalformedOne) {
  const ParseResult r = ParseNmea(WithNmeaChecksum("IIMWV,,,,,V"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  EXPECT_EQ(r.reading.status, "V");
  EXPECT_TRUE(std::isnan(r.reading.speed));
  // With status A an empty sentence is still malformed: a valid reading needs its fields.
  EXPECT_EQ(ParseNmea(WithNmeaChecksum("IIMWV,,,,,A")).status, ParseStatus::kMalformed);
}

TEST(Nmea, MwvStatusVoidIsAnInvalidReading) {
  ParseResult r = ParseNmea("$IIMWV,270.0,R,3.0,N,V*2C");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  r = ParseNmea("$IIMWV,,R,,N,V*2A");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  EXPECT_TRUE(std::isnan(r.reading.speed));
  EXPECT_TRUE(std::isnan(WindDirection(r.reading)));
}

// A void reading whose fields hold a failed measurement's filler (a WindSonic with status codes
// pads them with 9s) or cannot be read: void, saying its status, not malformed naming a field. It
// keeps what it can read.
TEST(Nmea, MwvVoidWithFieldsOutOfRangeIsAnInvalidReadingNotAMalformedOne) {
  ParseResult r = ParseNmea(WithNmeaChecksum("IIMWV,999,R,999.99,M,04"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  EXPECT_NE(r.reading.status.find("axis 1 and 2 failed"), std::string::npos) << r.reading.status;
  EXPECT_TRUE(std::isnan(r.reading.speed));
  EXPECT_TRUE(std::isnan(WindDirection(r.reading)));
  for (const char* sentence : {"IIMWV,-5,R,-1.0,M,V", "IIMWV,12x,Q,abc,Z,V", "IIMWV,400,T,2.0,?,V"}) {
    r = ParseNmea(WithNmeaChecksum(sentence));
    ASSERT_EQ(r.status, ParseStatus::kOk) << sentence << ": " << r.error;
    EXPECT_FALSE(r.reading.valid) << sentence;
    EXPECT_TRUE(std::isnan(r.reading.speed)) << sentence;
    EXPECT_TRUE(std::isnan(WindDirection(r.reading))) << sentence;
  }
  r = ParseNmea(WithNmeaChecksum("IIMWV,270.0,R,3.0,M,V"));  // readable: kept
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  EXPECT_DOUBLE_EQ(r.reading.speed, 3.0);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 270.0);
  // The same fields under status A stay malformed, naming the field.
  r = ParseNmea(WithNmeaChecksum("IIMWV,999,R,2.0,M,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 1 (angle)"), std::string::npos) << r.error;
}

TEST(Nmea, MwvWithAGillStatusCodeIsReadAsTheGillCode) {
  // A WindSonic in NMEA mode with Gill status codes (its manual's "$IIMWV,120,R,002.10,M,00"):
  // every record was refused as "expected A or V".
  ParseResult r = ParseNmea("$IIMWV,120,R,002.10,M,00*51");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_TRUE(r.reading.valid);
  EXPECT_DOUBLE_EQ(r.reading.speed, 2.10);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 120.0);
  EXPECT_EQ(r.reading.status, "00 ok");
  r = ParseNmea(WithNmeaChecksum("IIMWV,120,R,002.10,M,04"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_FALSE(r.reading.valid);
  EXPECT_NE(r.reading.status.find("axis 1 and 2 failed"), std::string::npos) << r.reading.status;
  EXPECT_EQ(ParseNmea(WithNmeaChecksum("IIMWV,120,R,002.10,M,0G")).status, ParseStatus::kMalformed);
}

TEST(Nmea, MwvInCalmAirHasASpeedAndNoDirection) {
  // The WindSonic leaves the angle empty below 0.05 m/s; so do marine instruments in calm air.
  // These were parse errors, and calm spells published nothing.
  for (const char* sentence : {"$IIMWV,,R,000.02,M,A*22", "$IIMWV,,R,1.4,N,A*16"}) {
    const ParseResult r = ParseNmea(sentence);
    ASSERT_EQ(r.status, ParseStatus::kOk) << sentence << ": " << r.error;
    EXPECT_TRUE(r.reading.valid);
    EXPECT_TRUE(std::isfinite(r.reading.speed));
    EXPECT_EQ(r.reading.reference, AngleReference::kNone);
    EXPECT_TRUE(std::isnan(WindDirection(r.reading)));
  }
  // A valid reading still needs its speed.
  const ParseResult r = ParseNmea(WithNmeaChecksum("IIMWV,120,R,,M,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 3"), std::string::npos) << r.error;
}

TEST(Nmea, BadChecksumIsRejected) {
  const ParseResult r = ParseNmea("$IIMWV,229.0,R,5.8,N,A*38");
  EXPECT_EQ(r.status, ParseStatus::kChecksumError);
  EXPECT_NE(r.error.find("38"), std::string::npos);
  EXPECT_NE(r.error.find("39"), std::string::npos);
  // One flipped digit in the payload is caught as well.
  EXPECT_EQ(ParseNmea("$IIMWV,228.0,R,5.8,N,A*39").status, ParseStatus::kChecksumError);
}

TEST(Nmea, MalformedSentencesNameTheProblem) {
  ParseResult r = ParseNmea(WithNmeaChecksum("IIMWV,229.0,R,5.8"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("5 fields"), std::string::npos) << r.error;
  r = ParseNmea(WithNmeaChecksum("IIMWV,229.0,R,5.8,X,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 4"), std::string::npos) << r.error;
  r = ParseNmea(WithNmeaChecksum("IIMWV,229.0,Q,5.8,N,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  r = ParseNmea(WithNmeaChecksum("IIMWV,229.0,R,5.8,N,B"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  r = ParseNmea(WithNmeaChecksum("IIMWV,400.0,R,5.8,N,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  r = ParseNmea(WithNmeaChecksum("IIMWV,22x.0,R,5.8,N,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  r = ParseNmea(WithNmeaChecksum("IIMWV,229.0,R,-5.8,N,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  r = ParseNmea(WithNmeaChecksum("IIMWV,229.0,R,nan,N,A"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseNmea("$IIMWV,229.0,R,5.8,N,A*3").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseNmea("$\x01\x7f\xff garbage").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseNmea("$").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseNmea("").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseNmea("IIMWV,229.0,R,5.8,N,A").status, ParseStatus::kMalformed);
}

TEST(Nmea, MwdPrefersTrueBearingAndMetresPerSecond) {
  const ParseResult r = ParseNmea("$WIMWD,270.0,T,265.5,M,10.0,N,5.1,M*6E");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 5.1);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 270.0);
  EXPECT_EQ(r.reading.reference, AngleReference::kEarth);
  EXPECT_FALSE(r.reading.relative);
  EXPECT_EQ(r.reading.source, "nmea_mwd");
  EXPECT_NEAR(WindDirection(r.reading), 0.0, 1e-12);  // a westerly blows east
}

TEST(Nmea, MwdFallsBackToKnotsAndMagnetic) {
  ParseResult r = ParseNmea(WithNmeaChecksum("WIMWD,,T,90.0,M,10.0,N,,M"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 10.0 * kKnot, 1e-9);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 90.0);
  EXPECT_EQ(r.reading.status, "magnetic");
  EXPECT_EQ(r.reading.reference, AngleReference::kMagnetic);
  // A magnetic bearing is no direction until the declination is known; with 10 deg east, an
  // easterly by the compass comes from 100 deg true and blows toward 280 deg: -x, slightly +y (ENU).
  EXPECT_TRUE(std::isnan(WindDirection(r.reading)));
  EXPECT_NEAR(WindDirection(r.reading, 10.0), DirectionFromBearing(100.0), 1e-12);
  EXPECT_NEAR(WindDirection(r.reading, 0.0), M_PI, 1e-12);  // an easterly blows west
  EXPECT_TRUE(std::isnan(WindVelocity(r.reading)[0]));
  EXPECT_NEAR(WindVelocity(r.reading, 10.0)[1], 10.0 * kKnot * std::sin(10.0 * M_PI / 180), 1e-9);
  r = ParseNmea(WithNmeaChecksum("WIMWD,90.0,T,,M,,N,,M"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  r = ParseNmea(WithNmeaChecksum("WIMWD,90.0,T,,M,10,K,,M"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
}

TEST(Nmea, XdrWindQuadruplets) {
  ParseResult r = ParseNmea("$WIXDR,A,225.0,D,WINDDIR,N,7.5,M,WINDSPEED*49");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 7.5);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 225.0);
  EXPECT_EQ(r.reading.source, "nmea_xdr");
  r = ParseNmea(WithNmeaChecksum("WIXDR,G,10.0,N,WSPD,G,20.0,N,WGUST"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_NEAR(r.reading.speed, 10.0 * kKnot, 1e-9);
  EXPECT_NEAR(r.reading.gust, 20.0 * kKnot, 1e-9);
  EXPECT_TRUE(std::isnan(r.reading.from_angle_deg));
  EXPECT_EQ(ParseNmea("$WIXDR,C,21.5,C,AIRTEMP,P,1.013,B,BARO*3F").status, ParseStatus::kNotWind);
  EXPECT_EQ(ParseNmea(WithNmeaChecksum("WIXDR,A,225.0,R,WINDDIR,N,7.5,M,WINDSPEED")).status,
            ParseStatus::kMalformed);
  EXPECT_EQ(ParseNmea(WithNmeaChecksum("WIXDR,A,225.0,D")).status, ParseStatus::kMalformed);
  // A wind chill in degrees Celsius beside the wind: it voided the whole sentence.
  r = ParseNmea("$WIXDR,C,-3.2,C,WINDCHILL,A,120,D,WDIR,S,5.0,M,WSPD*1F");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 5.0);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 120.0);
  // F and P are Gill's MWV units, not XDR's: a wind chill of 40 F was read as 40 ft/min of wind,
  // over the sentence's own WSPD.
  r = ParseNmea(WithNmeaChecksum("WIXDR,A,120,D,WDIR,S,5.0,M,WSPD,C,40,F,WINDCHILL"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 5.0);
  r = ParseNmea(WithNmeaChecksum("WIXDR,A,120,D,WDIR,S,5.0,M,WSPD,C,-4,F,WINDCHILL"));
  EXPECT_EQ(r.status, ParseStatus::kOk) << r.error;  // (it voided the sentence: a negative speed)
  r = ParseNmea(WithNmeaChecksum("WIXDR,S,5.0,P,WSPD"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("speed units expected M, N, K or S, got 'P'"), std::string::npos) << r.error;
  // Several speeds, gusts or directions (an average or maximum beside the value): the plain
  // name's is read, else the first's; the last overwrote the others without a word.
  r = ParseNmea(WithNmeaChecksum("WIXDR,S,4.8,M,WSPD_AVG,S,5.2,M,WSPD,A,270,D,WDIR,A,265,D,WDIR_AVG"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 5.2);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 270.0);
  r = ParseNmea(WithNmeaChecksum("WIXDR,S,7.9,M,WINDSPEEDMAX,S,6.0,M,WINDSPEEDAVG,S,9.0,M,WGUSTMAX,S,8.0,M,WINDGUST"));
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 7.9);  // no plain name: the first
  EXPECT_DOUBLE_EQ(r.reading.gust, 8.0);
  // WSPD is wind whatever its units, so wrong ones are still an error.
  r = ParseNmea(WithNmeaChecksum("WIXDR,S,5.0,C,WSPD"));
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("WSPD"), std::string::npos) << r.error;
}

// MWD's knots and m/s must say one speed within their rounding: "20 N, 1 M" was read as 1 m/s.
TEST(Nmea, MwdSpeedsThatDisagreeAreRefused) {
  ParseResult r = ParseNmea(WithNmeaChecksum("WIMWD,270,T,,M,20,N,1,M"));
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 5 (20 kn, 10.3 m/s) and field 7 (1 m/s) disagree"), std::string::npos) << r.error;
  // Rounded to 0.1 each: 19.4 kn is 9.98 m/s, said as 10.0.
  r = ParseNmea(WithNmeaChecksum("WIMWD,270,T,,M,19.4,N,10.0,M"));
  EXPECT_EQ(r.status, ParseStatus::kOk) << r.error;
  r = ParseNmea(WithNmeaChecksum("WIMWD,270,T,,M,0.1,N,0.0,M"));
  EXPECT_EQ(r.status, ParseStatus::kOk) << r.error;
  // Whole numbers carry half a unit each: 12 kn is 6.17 m/s, printed 6; 3 kn, 1.54, printed 2.
  for (const char* whole : {"WIMWD,270,T,,M,12,N,6,M", "WIMWD,270,T,,M,3,N,2,M"}) {
    r = ParseNmea(WithNmeaChecksum(whole));
    EXPECT_EQ(r.status, ParseStatus::kOk) << whole << ": " << r.error;
  }
}

TEST(Nmea, MwdDirectionOutOfRangeNamesTheFieldAndValue) {
  ParseResult r = ParseNmea("$WIMWD,400.0,T,,M,10.0,N,5.1,M*45");
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 1"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("400.0"), std::string::npos) << r.error;
  r = ParseNmea(WithNmeaChecksum("WIMWD,,T,-7,M,10.0,N,5.1,M"));
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 3"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("-7"), std::string::npos) << r.error;
}

TEST(Nmea, TrailingBlanksAreIgnored) {
  for (const std::string& s : {std::string("$IIMWV,229.0,R,5.8,N,A*39 "), std::string("$IIMWV,229.0,R,5.8,N,A \t")}) {
    const ParseResult r = ParseNmea(s);
    EXPECT_EQ(r.status, ParseStatus::kOk) << r.error;
  }
}

TEST(Nmea, NegativeSpeedNamesTheFieldAndValue) {
  // MWD reads m/s (field 7) before knots (field 5): the field read is the one named.
  ParseResult r = ParseNmea(WithNmeaChecksum("WIMWD,270.0,T,265.5,M,10.0,N,-5.1,M"));
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 7 (speed, m/s): expected >= 0, got -5.1"), std::string::npos) << r.error;
  r = ParseNmea(WithNmeaChecksum("WIMWD,270.0,T,265.5,M,-10.0,N,,M"));
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 5 (speed, knots): expected >= 0, got -10.0"), std::string::npos) << r.error;
  r = ParseNmea(WithNmeaChecksum("WIXDR,A,225.0,D,WINDDIR,N,-7.5,M,WINDSPEED"));
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("'WINDSPEED' field 6 (speed): expected >= 0, got -7.5"), std::string::npos) << r.error;
  // A direction out of 0..360 is named with its field here, as MWV's angle is.
  r = ParseNmea(WithNmeaChecksum("WIXDR,A,-10.0,D,WINDDIR,N,7.5,M,WINDSPEED"));
  ASSERT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("'WINDDIR' field 2 (direction): expected 0..360 deg, got -10.0"), std::string::npos) << r.error;
}

}  // namespace
}  // namespace clothwind::sensors
