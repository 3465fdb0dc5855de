#include "sensors/anemometer_stream.h"

#include <string>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

void Feed(RecordFramer* f, const std::string& s, double t, std::vector<RawRecord>* out) {
  f->Feed(reinterpret_cast<const uint8_t*>(s.data()), s.size(), t, out);
}

TEST(RecordFramer, SplitsLinesAndStampsFirstByte) {
  RecordFramer f;
  std::vector<RawRecord> out;
  Feed(&f, "$IIMWV,229.0,R,", 1.0, &out);
  EXPECT_TRUE(out.empty());
  Feed(&f, "5.8,N,A*39\r\n$IIMWV,1", 2.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data, "$IIMWV,229.0,R,5.8,N,A*39");
  EXPECT_DOUBLE_EQ(out[0].stamp, 1.0);
  Feed(&f, "\n", 3.0, &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].data, "$IIMWV,1");
  EXPECT_DOUBLE_EQ(out[1].stamp, 2.0);
}

TEST(RecordFramer, GillRecordsKeepStxEtx) {
  RecordFramer f;
  std::vector<RawRecord> out;
  const std::string rec = std::string("\x02") + "Q,229,002.74,M,00," + "\x03" + "16";
  Feed(&f, rec + "\r\n" + rec + "\r\n", 5.0, &out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].data, rec);
  EXPECT_EQ(out[1].data, rec);
}

TEST(RecordFramer, StartDelimiterDropsNoiseBeforeIt) {
  RecordFramer f;
  std::vector<RawRecord> out;
  Feed(&f, std::string("A*39\xff\x00junk$IIMWV,1\r", 19), 1.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data, "$IIMWV,1");
  EXPECT_GT(f.dropped_bytes(), 4u);
}

TEST(RecordFramer, OverlongRecordsAreDroppedWhole) {
  RecordFramer f(16);
  std::vector<RawRecord> out;
  Feed(&f, "\n" + std::string(100, 'x') + "\n1,2\n", 1.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data, "1,2");
  EXPECT_EQ(f.overlong_records(), 1u);
}

// After Reset (a reconnect) the partial record is forgotten, and so is the reopened port's first
// line, which may be cut: "0" was framed as a record of its own.
TEST(RecordFramer, ResetForgetsPartialRecordAndTheCutLineAfterIt) {
  RecordFramer f;
  std::vector<RawRecord> out;
  Feed(&f, "\n3.5,9", 1.0, &out);
  f.Reset();
  const size_t dropped = f.dropped_bytes();
  EXPECT_EQ(dropped, 5u);
  Feed(&f, "0\n1.5,45\n", 2.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data, "1.5,45");
  EXPECT_EQ(f.dropped_bytes(), dropped + 1);
}

// A port opened while the instrument is half-way through a line: the CSV tail up to the first line
// end is dropped (it read "35,270" of "12.35,270" as 35 m/s); a start delimiter needs no line end
// first.
TEST(RecordFramer, ANewFramerDropsTheCutFirstLine) {
  RecordFramer csv;
  std::vector<RawRecord> out;
  Feed(&csv, "35,270\r\n12.40,271\r\n", 1.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data, "12.40,271");
  EXPECT_EQ(csv.dropped_bytes(), 6u);
  RecordFramer nmea;
  out.clear();
  Feed(&nmea, "9*39$IIMWV,1\r\n", 1.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].data, "$IIMWV,1");
  RecordFramer gill;
  out.clear();
  Feed(&gill, std::string("\x02") + "Q,229\r\n", 1.0, &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(gill.dropped_bytes(), 0u);
}

}  // namespace
}  // namespace clothwind::sensors
