#include "sensors/fine_offset_record.h"

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

// A WH1080 record laid out byte by byte as the public memory map documents it:
// delay 5 min, indoor 45 % 21.0 C, outdoor 80 % 13.8 C, 1011.0 hPa, wind average 2.8 m/s,
// gust 29.8 m/s (low byte 0x2A plus high nibble 1 in byte 11), direction 6 (SE), rain 0x0124.
const std::vector<uint8_t> kRecord = {0x05, 0x2D, 0xD2, 0x00, 0x50, 0x8A, 0x00, 0x7E,
                                      0x27, 0x1C, 0x2A, 0x10, 0x06, 0x24, 0x01, 0x00};

TEST(FineOffsetRecord, DecodesTheDocumentedLayout) {
  FineOffsetRecord r;
  std::string err;
  ASSERT_TRUE(ParseFineOffsetRecord(kRecord, &r, &err)) << err;
  EXPECT_EQ(r.delay_minutes, 5);
  EXPECT_EQ(r.humidity_out, 80);
  EXPECT_NEAR(r.temperature_out, 13.8, 1e-9);
  EXPECT_NEAR(r.pressure_abs, 1011.0, 1e-9);
  EXPECT_NEAR(r.wind_average, 2.8, 1e-9);
  EXPECT_NEAR(r.wind_gust, 29.8, 1e-9);
  EXPECT_EQ(r.direction_index, 6);
  EXPECT_FALSE(r.lost_contact);
}

TEST(FineOffsetRecord, HighNibblesExtendBothSpeeds) {
  std::vector<uint8_t> b = kRecord;
  b[11] = 0x21;  // average += 0x100, gust += 0x200
  FineOffsetRecord r;
  std::string err;
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  EXPECT_NEAR(r.wind_average, (0x1C + 0x100) * 0.1, 1e-9);
  EXPECT_NEAR(r.wind_gust, (0x2A + 0x200) * 0.1, 1e-9);
}

// A void reading keeps only possible speeds: a lost sensor's record with an average of 389 m/s
// (found by fuzzing) was published, flagged invalid, at 389 m/s.
TEST(FineOffsetRecord, AVoidReadingCarriesNoImpossibleSpeed) {
  std::vector<uint8_t> b = kRecord;
  b[9] = 0xF3;
  b[10] = 0x0F;
  b[11] = 0x0F;  // average 0xFF3 (409.1 m/s), gust 0x00F (1.5 m/s)
  b[15] = 0x40;  // lost contact
  FineOffsetRecord r;
  std::string err;
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err)) << err;
  const WindReading lost = FineOffsetToReading(r);
  EXPECT_FALSE(lost.valid);
  EXPECT_TRUE(std::isnan(lost.speed)) << lost.speed;
  EXPECT_NEAR(lost.gust, 1.5, 1e-9);  // possible: kept
  b[15] = 0x00;
  b[9] = 0xFF;
  b[10] = 0xFE;
  b[11] = 0xFF;  // no average (0xFFF), gust 0xFFE: void, and the gust of 409.4 m/s dropped
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err)) << err;
  const WindReading no_average = FineOffsetToReading(r);
  EXPECT_FALSE(no_average.valid);
  EXPECT_TRUE(std::isnan(no_average.gust)) << no_average.gust;
  b[9] = 0x1C;
  b[10] = 0x2A;
  b[11] = 0x10;  // the documented record: valid, its values as they are
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err)) << err;
  EXPECT_NEAR(FineOffsetToReading(r).gust, 29.8, 1e-9);
}

TEST(FineOffsetRecord, NegativeTemperatureIsSignMagnitude) {
  std::vector<uint8_t> b = kRecord;
  b[5] = 0x05;
  b[6] = 0x80;
  FineOffsetRecord r;
  std::string err;
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  EXPECT_NEAR(r.temperature_out, -0.5, 1e-9);
}

TEST(FineOffsetRecord, InvalidFlags) {
  std::vector<uint8_t> b = kRecord;
  b[12] = 0x86;  // bit 7: direction invalid
  FineOffsetRecord r;
  std::string err;
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  EXPECT_EQ(r.direction_index, -1);
  WindReading w = FineOffsetToReading(r);
  EXPECT_TRUE(w.valid);
  EXPECT_TRUE(std::isnan(WindDirection(w)));

  b = kRecord;
  b[15] = 0x40;  // lost contact with the outdoor unit
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  EXPECT_TRUE(r.lost_contact);
  EXPECT_FALSE(FineOffsetToReading(r).valid);

  b = kRecord;
  b[9] = 0xFF;  // no average: all twelve bits set
  b[11] = 0x1F;
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  EXPECT_TRUE(std::isnan(r.wind_average));
  EXPECT_NEAR(r.wind_gust, (0x2A + 0x100) * 0.1, 1e-9);
  EXPECT_FALSE(FineOffsetToReading(r).valid);
  EXPECT_EQ(FineOffsetToReading(r).status, "no wind average");

  // A low byte 0xFF alone is a gale, 25.5 m/s (0x0FF) or 51.1 (0x1FF), not "no data" (it was).
  b = kRecord;
  b[9] = 0xFF;
  b[10] = 0xFF;
  b[11] = 0x10;
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  EXPECT_NEAR(r.wind_average, 25.5, 1e-9);
  EXPECT_NEAR(r.wind_gust, 51.1, 1e-9);
  EXPECT_TRUE(FineOffsetToReading(r).valid);

  b = kRecord;
  b[9] = 0x00;  // calm: the vane's position means nothing
  ASSERT_TRUE(ParseFineOffsetRecord(b, &r, &err));
  w = FineOffsetToReading(r);
  EXPECT_TRUE(w.valid);
  EXPECT_EQ(w.speed, 0.0);
  EXPECT_TRUE(std::isnan(WindDirection(w)));
  EXPECT_EQ(WindVelocity(w)[0], 0.0);

  EXPECT_FALSE(ParseFineOffsetRecord({0x01, 0x02}, &r, &err));
  EXPECT_NE(err.find("16"), std::string::npos);
}

TEST(FineOffsetRecord, ReadingUsesCompassConvention) {
  FineOffsetRecord r;
  std::string err;
  ASSERT_TRUE(ParseFineOffsetRecord(kRecord, &r, &err));
  const WindReading w = FineOffsetToReading(r);
  EXPECT_EQ(w.source, "fine_offset");
  EXPECT_DOUBLE_EQ(w.from_angle_deg, 135.0);  // index 6 * 22.5: from the south-east
  EXPECT_EQ(w.reference, AngleReference::kEarth);
  EXPECT_NEAR(WindDirection(w), 3 * M_PI / 4, 1e-12);  // blowing to the north-west in ENU
  EXPECT_NEAR(w.gust, 29.8, 1e-9);
}

TEST(FineOffsetRecord, CurrentAddressFromFixedBlock) {
  std::vector<uint8_t> fixed(32, 0);
  fixed[0] = 0x55;
  fixed[1] = 0xAA;
  fixed[0x1E] = 0x40;
  fixed[0x1F] = 0x05;
  uint16_t a = 0;
  std::string err;
  ASSERT_TRUE(FineOffsetCurrentAddress(fixed, &a, &err)) << err;
  EXPECT_EQ(a, 0x0540);
  fixed[0x1F] = 0x00;
  fixed[0x1E] = 0x10;  // inside the fixed block: corrupt read
  EXPECT_FALSE(FineOffsetCurrentAddress(fixed, &a, &err));
  EXPECT_NE(err.find("0x0010"), std::string::npos);
  EXPECT_FALSE(FineOffsetCurrentAddress(std::vector<uint8_t>(16, 0), &a, &err));
}

TEST(FineOffsetRecord, ReadCommandAndHex) {
  const auto c = FineOffsetReadCommand(0x0540);
  const std::array<uint8_t, 8> expected = {0xA1, 0x05, 0x40, 0x20, 0xA1, 0x05, 0x40, 0x20};
  EXPECT_EQ(c, expected);
  const std::string hex = HexEncode(kRecord);
  EXPECT_EQ(hex, "052DD200508A007E271C2A1006240100");
  std::vector<uint8_t> back;
  ASSERT_TRUE(HexDecode(hex, &back));
  EXPECT_EQ(back, kRecord);
  EXPECT_FALSE(HexDecode("0A1", &back));
  EXPECT_FALSE(HexDecode("0G", &back));
  const ParseResult p = ParseFineOffsetHex(hex);
  ASSERT_EQ(p.status, ParseStatus::kOk) << p.error;
  EXPECT_NEAR(p.reading.speed, 2.8, 1e-9);
  EXPECT_EQ(ParseFineOffsetHex("zz").status, ParseStatus::kMalformed);
  // A WH3080 record (20 bytes, the same first 16) reads the same wind.
  const ParseResult wh3080 = ParseFineOffsetHex(hex + "00000000");
  ASSERT_EQ(wh3080.status, ParseStatus::kOk) << wh3080.error;
  EXPECT_NEAR(wh3080.reading.speed, 2.8, 1e-9);
  // Any other length is no one record: 17 bytes, two records run together, 15 bytes.
  for (const std::string& bad : {hex + "FF", hex + hex, hex.substr(0, 30)}) {
    const ParseResult p2 = ParseFineOffsetHex(bad);
    EXPECT_EQ(p2.status, ParseStatus::kMalformed) << bad;
    EXPECT_NE(p2.error.find("expected 16"), std::string::npos) << p2.error;
  }
}

}  // namespace
}  // namespace clothwind::sensors
