#include "sensors/anemometer_protocol.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sensors/csv_wind.h"
#include "sensors/gill_windsonic.h"
#include "sensors/nmea.h"

namespace clothwind::sensors {
namespace {

const std::string kMwv = "$IIMWV,229.0,R,5.8,N,A*39";
const std::string kGill = std::string("\x02") + "Q,229,002.74,M,00," + "\x03" + "16";

TEST(AnemometerProtocol, Names) {
  AnemometerProtocol p;
  for (auto q : {AnemometerProtocol::kAuto, AnemometerProtocol::kNmea, AnemometerProtocol::kGill,
                 AnemometerProtocol::kCsv, AnemometerProtocol::kFineOffset}) {
    ASSERT_TRUE(ParseAnemometerProtocol(AnemometerProtocolName(q), &p));
    EXPECT_EQ(p, q);
  }
  EXPECT_TRUE(ParseAnemometerProtocol("", &p));
  EXPECT_EQ(p, AnemometerProtocol::kAuto);
  EXPECT_FALSE(ParseAnemometerProtocol("NMEA2000", &p));
}

TEST(AnemometerProtocol, ClassifiesByBytes) {
  EXPECT_EQ(ClassifyAnemometerRecord(kMwv), AnemometerProtocol::kNmea);
  EXPECT_EQ(ClassifyAnemometerRecord(kGill), AnemometerProtocol::kGill);
  EXPECT_EQ(ClassifyAnemometerRecord("3.2,270"), AnemometerProtocol::kCsv);
  EXPECT_EQ(ClassifyAnemometerRecord(" 3.2 , 270 , 5.1"), AnemometerProtocol::kCsv);
  EXPECT_EQ(ClassifyAnemometerRecord("speed,direction"), AnemometerProtocol::kCsv);
  EXPECT_EQ(ClassifyAnemometerRecord("052DD200508A007E271C2A1006240100"), AnemometerProtocol::kFineOffset);
  EXPECT_EQ(ClassifyAnemometerRecord("hello world"), AnemometerProtocol::kAuto);
  EXPECT_EQ(ClassifyAnemometerRecord("1,2,3,4"), AnemometerProtocol::kAuto);
  EXPECT_EQ(ClassifyAnemometerRecord(""), AnemometerProtocol::kAuto);
  EXPECT_EQ(ClassifyAnemometerRecord("\xff\xfe\x01"), AnemometerProtocol::kAuto);
}

TEST(CsvWind, ParsesSpeedDirectionGust) {
  ParseResult r = ParseCsvWind("3.25,270");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.speed, 3.25);
  EXPECT_DOUBLE_EQ(r.reading.from_angle_deg, 270.0);
  EXPECT_NEAR(WindDirection(r.reading), -M_PI / 2, 1e-12);
  r = ParseCsvWind("3.25, 90, 6.5");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_DOUBLE_EQ(r.reading.gust, 6.5);
  r = ParseCsvWind("0.0,");
  ASSERT_EQ(r.status, ParseStatus::kOk) << r.error;
  EXPECT_TRUE(std::isnan(r.reading.from_angle_deg));
  EXPECT_EQ(ParseCsvWind("Speed,Direction").status, ParseStatus::kNotWind);
  r = ParseCsvWind("-1,90");
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 1"), std::string::npos);
  r = ParseCsvWind("1,361");
  EXPECT_EQ(r.status, ParseStatus::kMalformed);
  EXPECT_NE(r.error.find("field 2"), std::string::npos);
  EXPECT_EQ(ParseCsvWind("1").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseCsvWind("1,2,3,4").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseCsvWind("1..2,3").status, ParseStatus::kMalformed);
  EXPECT_EQ(ParseCsvWind(",90").status, ParseStatus::kMalformed);
}

TEST(AnemometerDecoder, AutoDetectLocksAfterThreeGoodRecords) {
  AnemometerDecoder d;
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kAuto);
  AnemometerProtocol used;
  for (int i = 0; i < 2; ++i) EXPECT_EQ(d.Decode(kGill, &used).status, ParseStatus::kOk);
  EXPECT_EQ(used, AnemometerProtocol::kGill);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kAuto);
  EXPECT_EQ(d.Decode(kGill).status, ParseStatus::kOk);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kGill);
  // Noise that happens to look like CSV is now rejected.
  const ParseResult noise = d.Decode("12,34");
  EXPECT_EQ(noise.status, ParseStatus::kMalformed);
  EXPECT_NE(noise.error.find("gill"), std::string::npos);
  EXPECT_EQ(d.counters().parse_errors, 1u);
  EXPECT_EQ(d.counters().readings, 3u);
}

TEST(AnemometerDecoder, BadRecordsDoNotLock) {
  AnemometerDecoder d;
  std::string bad = kMwv;
  bad.back() = '8';
  for (int i = 0; i < 5; ++i) EXPECT_EQ(d.Decode(bad).status, ParseStatus::kChecksumError);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kAuto);
  EXPECT_EQ(d.counters().checksum_failures, 5u);
  EXPECT_EQ(d.Decode("\x01\x02garbage").status, ParseStatus::kMalformed);
  EXPECT_FALSE(d.last_error().empty());
  EXPECT_EQ(d.counters().parse_errors, 1u);
}

TEST(AnemometerDecoder, SwitchesAfterAReconfiguredInstrumentProvesItself) {
  AnemometerDecoder d(AnemometerProtocol::kAuto, 3, 10);
  for (int i = 0; i < 3; ++i) d.Decode(kMwv);
  ASSERT_EQ(d.protocol(), AnemometerProtocol::kNmea);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(d.Decode(kGill).status, ParseStatus::kMalformed);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kNmea);
  EXPECT_EQ(d.Decode(kGill).status, ParseStatus::kOk);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kGill);
}

TEST(AnemometerDecoder, NmeaWithoutWindCountsTowardsLockButGivesNoReading) {
  AnemometerDecoder d;
  const std::string gga = "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47";
  for (int i = 0; i < 3; ++i) EXPECT_EQ(d.Decode(gga).status, ParseStatus::kNotWind);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kNmea);
  EXPECT_EQ(d.counters().readings, 0u);
  EXPECT_EQ(d.counters().not_wind, 3u);
}

TEST(AnemometerDecoder, FixedProtocolParsesEverythingWithIt) {
  AnemometerDecoder d(AnemometerProtocol::kCsv);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kCsv);
  EXPECT_EQ(d.Decode(kMwv).status, ParseStatus::kMalformed);
  EXPECT_EQ(d.Decode("1.5,45").status, ParseStatus::kOk);
}

}  // namespace
}  // namespace clothwind::sensors
