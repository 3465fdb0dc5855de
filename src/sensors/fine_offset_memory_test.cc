// Fetching the current record from a station's memory through a fake memory image: aligned
// reads, the record grids of both station classes, the top of memory, the fixed block's magic
// and pointer checks, and reads repeated until the console stops writing.
#include "sensors/fine_offset_memory.h"

#include <cstdint>
#include <functional>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {

// 64 KiB of station memory: fixed block with magic 55 AA and the pointer at 0x1E, every other
// byte its own address's low byte plus its high byte (so any misplaced slice shows).
struct Station {
  std::vector<uint8_t> memory = std::vector<uint8_t>(0x10000);
  std::vector<uint16_t> reads;  // addresses asked for
  // Called before each read: lets a test change memory between reads (a console writing).
  std::function<void(int read_index)> before_read;

  explicit Station(uint16_t current) {
    for (size_t a = 0; a < memory.size(); ++a) memory[a] = static_cast<uint8_t>(a + (a >> 8));
    memory[0] = 0x55;
    memory[1] = 0xAA;
    SetPointer(current);
  }
  void SetPointer(uint16_t a) {
    memory[0x1E] = a & 0xFF;
    memory[0x1F] = a >> 8;
  }
  FineOffsetBlockReader Reader() {
    return [this](uint16_t address, std::vector<uint8_t>* chunk, std::string* error) {
      if (address % 32 != 0) {
        *error = "unaligned read";
        return false;
      }
      if (before_read) before_read(static_cast<int>(reads.size()));
      reads.push_back(address);
      chunk->assign(memory.begin() + address, memory.begin() + address + 32);
      return true;
    };
  }
  std::vector<uint8_t> At(uint16_t a) const { return {memory.begin() + a, memory.begin() + a + 16}; }
};

TEST(FineOffsetMemory, ReadsTheRecordThroughAlignedBlocksOnBothGrids) {
  // 16-byte grid (WH1080): 0x0110 is the second half of block 0x0100; 20-byte grid (WH3080):
  // 0x0114 crosses into block 0x0120; the top of memory: 0xFFF0 and 0xFFEC.
  for (const uint16_t current : {0x0100, 0x0110, 0x0114, 0x1234 - 0x1234 % 16, 0xFFEC, 0xFFF0}) {
    Station s(current);
    std::vector<uint8_t> record;
    uint16_t address = 0;
    std::string error;
    ASSERT_TRUE(ReadFineOffsetCurrentRecord(s.Reader(), &record, &address, &error)) << std::hex << current << error;
    EXPECT_EQ(address, current);
    EXPECT_EQ(record, s.At(current)) << std::hex << current;
    for (const uint16_t a : s.reads) EXPECT_LE(a, 0xFFE0);
  }
}

TEST(FineOffsetMemory, RefusesAPointerOffTheGridOrOutsideTheRecords) {
  for (const auto& [magic0, magic1, pointer, expected] : std::vector<std::tuple<int, int, int, std::string>>{
           {0x55, 0xAA, 0x0108, "neither record grid"},
           {0x55, 0xAA, 0x00F0, "outside 0x0100..0xFFF0"}}) {
    Station s(static_cast<uint16_t>(pointer));
    s.memory[0] = static_cast<uint8_t>(magic0);
    s.memory[1] = static_cast<uint8_t>(magic1);
    std::vector<uint8_t> record;
    uint16_t address = 0;
    std::string error;
    EXPECT_FALSE(ReadFineOffsetCurrentRecord(s.Reader(), &record, &address, &error));
    EXPECT_NE(error.find(expected), std::string::npos) << error;
  }
}

TEST(FineOffsetMemory, ReadsConsolesWhateverTheirFixedBlockStartsWith) {
  // The first two bytes consoles are known to write (pywws, wview and weewx's lists; 44 BF a new
  // WS2080A's): each station is read, not refused as out of step.
  for (const auto& [magic0, magic1] : std::vector<std::pair<int, int>>{
           {0x55, 0xAA}, {0xFF, 0xFF}, {0x55, 0x55}, {0xC4, 0x00}, {0x01, 0x1E}, {0x00, 0x01}, {0x44, 0xBF}}) {
    Station s(0x0540);
    s.memory[0] = static_cast<uint8_t>(magic0);
    s.memory[1] = static_cast<uint8_t>(magic1);
    std::vector<uint8_t> record;
    uint16_t address = 0;
    std::string error;
    EXPECT_TRUE(ReadFineOffsetCurrentRecord(s.Reader(), &record, &address, &error)) << error;
    EXPECT_EQ(address, 0x0540);
    EXPECT_EQ(record, s.At(0x0540));
  }
}

TEST(FineOffsetMemory, ReadsAgainWhileTheConsoleWrites) {
  // The pointer moves between the first two reads of the fixed block (0x10F0 -> 0x1100): the
  // record at the new pointer is the one taken, not one at a pointer read once.
  Station s(0x10F0);
  s.before_read = [&s](int i) {
    if (i == 1) s.SetPointer(0x1100);
  };
  std::vector<uint8_t> record;
  uint16_t address = 0;
  std::string error;
  ASSERT_TRUE(ReadFineOffsetCurrentRecord(s.Reader(), &record, &address, &error)) << error;
  EXPECT_EQ(address, 0x1100);
  EXPECT_EQ(record, s.At(0x1100));
  // A record rewritten on every read never settles: refused, not taken half written.
  Station busy(0x0200);
  busy.before_read = [&busy](int i) { busy.memory[0x0209] = static_cast<uint8_t>(i); };
  EXPECT_FALSE(ReadFineOffsetCurrentRecord(busy.Reader(), &record, &address, &error));
  EXPECT_NE(error.find("kept changing"), std::string::npos) << error;
}

TEST(FineOffsetMemory, OnlyTheWindAndStatusBytesCountAsAChange) {
  std::vector<uint8_t> a(16, 0x10), b = a;
  for (const size_t i : {0, 1, 2, 3, 4, 5, 6, 7, 8, 13, 14}) b[i] ^= 0xFF;  // delay, indoor, pressure, rain
  EXPECT_FALSE(FineOffsetWindBytesDiffer(a, b));
  for (const size_t i : {9, 10, 11, 12, 15}) {
    std::vector<uint8_t> c = a;
    c[i] ^= 0x01;
    EXPECT_TRUE(FineOffsetWindBytesDiffer(a, c)) << i;
  }
  EXPECT_TRUE(FineOffsetWindBytesDiffer(a, std::vector<uint8_t>(8)));
}

TEST(FineOffsetMemory, ThePublishGatePassesChangesAndOneRecordASensorPeriod) {
  FineOffsetPublishGate gate;
  std::vector<uint8_t> steady(16, 0x20);
  EXPECT_TRUE(gate.ShouldPublish(steady, 100.0));  // the first
  std::vector<uint8_t> minute = steady;
  minute[0] = 0x21;  // the delay byte counts a minute: the same wind
  EXPECT_FALSE(gate.ShouldPublish(minute, 110.0));
  EXPECT_FALSE(gate.ShouldPublish(minute, 147.9));
  EXPECT_TRUE(gate.ShouldPublish(minute, 148.0));  // a sensor period on: steady wind, a new reading
  std::vector<uint8_t> gust = minute;
  gust[10] = 0x30;
  EXPECT_TRUE(gate.ShouldPublish(gust, 150.0));  // the wind changed: at once
  EXPECT_FALSE(gate.ShouldPublish(gust, 160.0));
}

}  // namespace
}  // namespace clothwind::sensors
