#include "sensors/fine_offset_memory.h"

#include <cstdio>

#include "sensors/fine_offset_record.h"

namespace clothwind::sensors {
namespace {

constexpr int kReadPairs = 3;

// `count` consecutive 32-byte blocks from `first`, read until two passes agree.
bool ReadStable(const FineOffsetBlockReader& read, uint16_t first, int count, const char* what,
                std::vector<uint8_t>* bytes, std::string* error) {
  std::vector<uint8_t> previous;
  for (int pass = 0; pass < 2 * kReadPairs; ++pass) {
    std::vector<uint8_t> now, chunk;
    for (int b = 0; b < count; ++b) {
      if (!read(static_cast<uint16_t>(first + 32 * b), &chunk, error)) return false;
      if (chunk.size() != kFineOffsetChunkSize) {
        *error = "fine_offset: a read of " + std::string(what) + " gave " + std::to_string(chunk.size()) +
                 " bytes, expected 32";
        return false;
      }
      now.insert(now.end(), chunk.begin(), chunk.end());
    }
    if (pass > 0 && now == previous) {
      *bytes = std::move(now);
      return true;
    }
    previous = std::move(now);
  }
  *error = "fine_offset USB: " + std::string(what) + " kept changing between reads";
  return false;
}

}  // namespace

bool ReadFineOffsetCurrentRecord(const FineOffsetBlockReader& read, std::vector<uint8_t>* record,
                                 uint16_t* address, std::string* error) {
  std::vector<uint8_t> fixed;
  if (!ReadStable(read, 0x0000, 1, "the fixed block", &fixed, error)) return false;
  // The fixed block's first two bytes are not checked: consoles write 55 AA, FF FF, 55 55, C4 00,
  // 01 1E, 44 BF and more (weewx's fousb.py lists those it met, "a brand new WS2080A console
  // reports 44 bf ... but performs just fine"); refusing all but two made such a station unusable.
  // The reads agreeing and the pointer on a record grid are what say a read is in step.
  if (!FineOffsetCurrentAddress(fixed, address, error)) return false;
  const unsigned from_start = *address - kFineOffsetDataStart;
  if (from_start % 16 != 0 && from_start % 20 != 0) {
    char msg[160];
    std::snprintf(msg, sizeof msg,
                  "fine_offset: current record address 0x%04X is on neither record grid (0x0100 + 16 n or 20 n)",
                  *address);
    *error = msg;
    return false;
  }
  const uint16_t block = *address & ~0x1F;
  const size_t offset = *address - block;
  const int blocks = offset + kFineOffsetRecordSize > kFineOffsetChunkSize ? 2 : 1;
  std::vector<uint8_t> bytes;
  if (!ReadStable(read, block, blocks, "the current record", &bytes, error)) return false;
  record->assign(bytes.begin() + offset, bytes.begin() + offset + kFineOffsetRecordSize);
  return true;
}

bool FineOffsetWindBytesDiffer(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
  if (a.size() < kFineOffsetRecordSize || b.size() < kFineOffsetRecordSize) return true;
  for (const size_t i : {9, 10, 11, 12, 15})
    if (a[i] != b[i]) return true;
  return false;
}

bool FineOffsetPublishGate::ShouldPublish(const std::vector<uint8_t>& record, double now) {
  if (any_ && !FineOffsetWindBytesDiffer(record, last_) && now - last_time_ < kFineOffsetSensorPeriod) return false;
  last_ = record;
  last_time_ = now;
  any_ = true;
  return true;
}

}  // namespace clothwind::sensors
