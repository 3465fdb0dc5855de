// How the current record is fetched from a Fine Offset station's memory, through any reader of
// 32-byte blocks (fine_offset_usb.h's libusb one, or a memory image in tests). The console keeps
// writing while it is read, so every block is read until two reads agree, as pywws does, and the
// pointer must lie on a record grid.
#ifndef CLOTHWIND_SENSORS_FINE_OFFSET_MEMORY_H_
#define CLOTHWIND_SENSORS_FINE_OFFSET_MEMORY_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace clothwind::sensors {

// Reads the 32 bytes at `address` (a multiple of 32) into `chunk`; false with `error` on failure.
using FineOffsetBlockReader =
    std::function<bool(uint16_t address, std::vector<uint8_t>* chunk, std::string* error)>;

// The current record: the fixed block's first 32 bytes read until two reads agree (at most 3
// pairs; its first two bytes, which differ between consoles, are not checked), its pointer inside 0x0100..0xFFF0 on the
// 16-byte (WH1080) or 20-byte (WH3080) record grid, then the 32-byte aligned block(s) holding the
// record read until two reads agree, and the record sliced out. Why aligned: pywws and weewx read
// only aligned blocks, and a console that ignores an address's low bits would answer an
// unaligned read with the block before, an older record.
// Inputs:
//   read  the block reader (addresses it is given are multiples of 32)
// Outputs:
//   record   16 bytes of the current record
//   address  its address
//   error    why it failed (the reader's error, a bad pointer, or a record or fixed
//            block that kept changing)
// Returns true on success.
bool ReadFineOffsetCurrentRecord(const FineOffsetBlockReader& read, std::vector<uint8_t>* record,
                                 uint16_t* address, std::string* error);

// Whether two current records differ in what a wind reading is made of: the wind bytes (9-12:
// average, gust, their high nibbles, direction) and the status byte (15). The console also
// rewrites the record when its delay byte counts a minute and when indoor values or pressure
// change; publishing on those republished one 48 s wind value with later stamps.
// Inputs: a, b  records of at least 16 bytes (shorter ones differ).
bool FineOffsetWindBytesDiffer(const std::vector<uint8_t>& a, const std::vector<uint8_t>& b);

// Which polled current records become readings: the first, one whose wind or status bytes
// differ from the last published (FineOffsetWindBytesDiffer), or one a sensor period
// (kFineOffsetSensorPeriod, 48 s) after the last published, since a steady wind is still a new
// measurement every transmission.
class FineOffsetPublishGate {
 public:
  // Inputs: record  the polled current record (16 bytes); now  the poll's time [s], any clock
  // that does not go back. Returns true when it is to be published (and remembers it).
  bool ShouldPublish(const std::vector<uint8_t>& record, double now);

 private:
  std::vector<uint8_t> last_;
  double last_time_ = 0;
  bool any_ = false;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_FINE_OFFSET_MEMORY_H_
