#include "sensors/anemometer_protocol.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "sensors/anemometer_stream.h"

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

TEST(AnemometerDecoder, LocksAfterGoodRecordsWithNoneOfAnotherProtocolBetween) {
  AnemometerDecoder d;
  std::string bad_checksum = kMwv;
  bad_checksum.back() = '8';
  // A good CSV record between Gill records starts the count again: not locked after 3 Gill.
  for (const std::string& r : {kGill, kGill, std::string("1.5,45"), kGill}) d.Decode(r);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kAuto);
  // Garbage and a checksum failure between Gill records count neither way: a noisy line locks.
  for (const std::string& r : {std::string("\x01\x02garbage"), bad_checksum, kGill}) d.Decode(r);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kAuto);
  d.Decode(kGill);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kGill);
  // Switching: ten good records of the new protocol with no good Gill record between them.
  for (int i = 0; i < 9; ++i) d.Decode(kMwv);
  d.Decode(kGill);
  d.Decode(kMwv);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kGill);
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

// An instrument that sends NMEA checksums sends them on every sentence: after three with one, a
// sentence without (its '*' lost to line noise, so nothing of it was checked: an XDR's free-form
// last field took "WINDSPEED+49" as a name) is a checksum failure. Ten good-looking sentences
// without one in a row are an instrument reconfigured, and are read from then on; a stream that
// never sent checksums is read throughout.
TEST(AnemometerDecoder, NmeaWithoutAChecksumFromAnInstrumentThatSendsThemIsAChecksumFailure) {
  const std::string bare = "$IIMWV,229.0,R,5.8,N,A";
  AnemometerDecoder d;
  for (int i = 0; i < 3; ++i) ASSERT_EQ(d.Decode(kMwv).status, ParseStatus::kOk);
  const ParseResult r = d.Decode(bare);
  EXPECT_EQ(r.status, ParseStatus::kChecksumError) << r.error;
  EXPECT_NE(r.error.find("no checksum"), std::string::npos) << r.error;
  EXPECT_EQ(d.counters().checksum_failures, 1u);
  const std::string xdr = "$IIXDR,A,225.0,D,WINDDIR,N,7.5,M,WINDSPEED+49";  // the '*' flipped to '+'
  EXPECT_EQ(d.Decode(xdr).status, ParseStatus::kChecksumError);
  EXPECT_EQ(d.Decode("$IIMWV,12").status, ParseStatus::kMalformed);  // malformed is said as such
  EXPECT_EQ(d.Decode(kMwv).status, ParseStatus::kOk);
  // Reconfigured to send none: refused until ten in a row would have been good.
  for (int i = 1; i < 10; ++i) EXPECT_EQ(d.Decode(bare).status, ParseStatus::kChecksumError) << i;
  for (int i = 0; i < 5; ++i) EXPECT_EQ(d.Decode(bare).status, ParseStatus::kOk) << i;
  AnemometerDecoder never;
  for (int i = 0; i < 20; ++i) EXPECT_EQ(never.Decode(bare).status, ParseStatus::kOk) << i;
}

// A multiplexer merging a GPS that sends checksums with a wind sensor that sends none: the wind
// sentences are read (they were refused 98 times in 100, one habit for the whole line), and the
// GPS's talker keeps its own check.
TEST(AnemometerDecoder, NmeaChecksumHabitsAreKeptPerTalker) {
  const std::string gga = WithNmeaChecksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
  const std::string wind = "$WIMWV,229.0,R,5.8,N,A";
  AnemometerDecoder d;
  int readings = 0;
  for (int i = 0; i < 50; ++i) {
    ASSERT_EQ(d.Decode(gga).status, ParseStatus::kNotWind) << i;
    const ParseResult r = d.Decode(wind);
    readings += r.status == ParseStatus::kOk;
  }
  EXPECT_EQ(readings, 50);
  EXPECT_EQ(d.counters().checksum_failures, 0u);
  const ParseResult lost = d.Decode("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
  EXPECT_EQ(lost.status, ParseStatus::kChecksumError) << lost.error;
  EXPECT_NE(lost.error.find("talker GP"), std::string::npos) << lost.error;
}

TEST(AnemometerDecoder, FixedProtocolParsesEverythingWithIt) {
  AnemometerDecoder d(AnemometerProtocol::kCsv);
  EXPECT_EQ(d.protocol(), AnemometerProtocol::kCsv);
  EXPECT_EQ(d.Decode(kMwv).status, ParseStatus::kMalformed);
  EXPECT_EQ(d.Decode("1.5,45").status, ParseStatus::kOk);
}

TEST(AnemometerDecoder, MutatedAndRandomBytesNeverGiveImpossibleReadings) {
  // Bit flips, truncations and random bytes around real records: the parsers must reject them or
  // return physically possible readings (a flip inside a CSV digit is a different valid number).
  const std::vector<std::string> seeds = {kMwv, kGill, "3.25,270,6.5", WithNmeaChecksum("WIMWD,270.0,T,265.5,M,10.0,N,5.1,M"),
                                          FrameGillRecord("Q,+001.59,-002.74,M,00,"),
                                          WithNmeaChecksum("WIXDR,A,225.0,D,WINDDIR,N,7.5,M,WINDSPEED")};
  std::mt19937 rng(12345);
  RecordFramer framer;
  AnemometerDecoder decoder;
  size_t ok = 0, checksum = 0;
  for (int i = 0; i < 20000; ++i) {
    std::string s = seeds[rng() % seeds.size()];
    switch (rng() % 4) {
      case 0: s[rng() % s.size()] ^= static_cast<char>(1u << (rng() % 8)); break;
      case 1: s.resize(rng() % s.size()); break;
      case 2: s.insert(rng() % s.size(), 1, static_cast<char>(rng() % 256)); break;
      default:
        for (auto& c : s) c = static_cast<char>(rng() % 256);
    }
    s += "\r\n";
    std::vector<RawRecord> records;
    framer.Feed(reinterpret_cast<const uint8_t*>(s.data()), s.size(), i, &records);
    for (const auto& r : records) {
      const ParseResult p = decoder.Decode(r.data);
      checksum += p.status == ParseStatus::kChecksumError;
      if (p.status != ParseStatus::kOk) continue;
      ++ok;
      const WindReading& w = p.reading;
      EXPECT_TRUE(std::isnan(w.speed) || (w.speed >= 0.0 && std::isfinite(w.speed))) << r.data;
      // The bearing as decoded (WindDirection wraps any angle into (-pi, pi], so it checked nothing).
      if (w.valid) {
        EXPECT_TRUE(std::isnan(w.from_angle_deg) || (w.from_angle_deg >= 0.0 && w.from_angle_deg <= 360.0))
            << r.data;
      }
    }
  }
  EXPECT_GT(ok, 0u);        // unharmed records (and harmless CSV flips) still parse
  EXPECT_GT(checksum, 100u);  // and flips inside checksummed records are caught
}

// A Gill record with its checksum (XOR of the bytes between STX and ETX, two hex digits).
std::string GillRecord(const std::string& body) {
  char hex[3];
  std::snprintf(hex, sizeof hex, "%02X", GillChecksum(body));
  return "\x02" + body + "\x03" + hex;
}

// A reading the instrument calls valid but that cannot be wind (a misread unit, a corrupt record
// whose checksum still matched) is a parse error naming the field, for every protocol; a reading
// flagged void is passed as it is (its numbers are not used).
TEST(AnemometerDecoder, ImplausibleReadingsAreParseErrors) {
  struct Case {
    std::string record, field;
  };
  const std::vector<Case> cases = {
      {WithNmeaChecksum("IIMWV,229.0,R,500.0,M,A"), "speed 500"},
      {WithNmeaChecksum("IIMWV,229.0,R,175.0,N,A"), "speed 90.0"},  // 175 kn = 90.03 m/s
      {WithNmeaChecksum("WIXDR,A,400.0,D,WINDDIR,N,7.5,M,WINDSPEED"), "'WINDDIR' field 2 (direction): expected 0..360 deg, got 400.0"},
      {WithNmeaChecksum("WIXDR,N,7.5,M,WINDSPEED,N,120,M,WINDGUST"), "gust 120"},
      {GillRecord("Q,229,095.00,M,00,"), "speed 95"},
      {"3.25,270,91", "gust 91"},
  };
  for (const auto& c : cases) {
    AnemometerDecoder d(AnemometerProtocol::kAuto);
    ParseResult r = d.Decode(c.record);
    EXPECT_EQ(r.status, ParseStatus::kMalformed) << c.record;
    EXPECT_NE(r.error.find(c.field), std::string::npos) << r.error;
    EXPECT_EQ(d.counters().parse_errors, 1u);
    EXPECT_EQ(d.counters().readings, 0u);
  }
  AnemometerDecoder d(AnemometerProtocol::kNmea);
  EXPECT_EQ(d.Decode(WithNmeaChecksum("IIMWV,229.0,R,89.9,M,A")).status, ParseStatus::kOk);
  EXPECT_EQ(d.Decode(WithNmeaChecksum("IIMWV,360.0,R,0.0,M,A")).status, ParseStatus::kOk);
  const ParseResult void_reading = d.Decode(WithNmeaChecksum("IIMWV,229.0,R,500.0,M,V"));
  EXPECT_EQ(void_reading.status, ParseStatus::kOk);
  EXPECT_FALSE(void_reading.reading.valid);
}

}  // namespace
}  // namespace clothwind::sensors
