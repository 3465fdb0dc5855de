// Pure parsing of Fine Offset WH1080/WH3080-class USB weather station memory (no I/O here; see
// fine_offset_usb.h). Layout, as publicly documented by the pywws project and Jim Easterbrook's
// memory map (reverse engineered, no manufacturer document exists):
//   - memory is read in 32-byte chunks addressed 0x0000..0xFFE0;
//   - the fixed block 0x0000..0x00FF holds, at 0x1E..0x1F (little endian), the address of the
//     record currently being written (the "current" reading);
//   - history records start at 0x0100, 16 bytes each (WH3080 class: 20, same first 16 bytes).
// Record bytes used here:
//   0      minutes since the previous stored record
//   9      wind average, low 8 bits     } value * 0.1 m/s; the 12-bit value 0xFFF means "no data"
//   10     wind gust, low 8 bits        }
//   11     high nibbles: bits 0-3 average bits 8-11, bits 4-7 gust bits 8-11
//   12     wind direction 0..15 (* 22.5 deg clockwise from north); bit 7 set = invalid
//   15     status: bit 6 = lost contact with the outdoor sensor, bit 7 = rain counter overflow
// (1 in/out humidity, 2-3 in temperature, 4 out humidity, 5-6 out temperature, 7-8 pressure,
// 13-14 rain counter are decoded too, for diagnostics.)
// The outdoor sensor transmits every 48 s, so the wind average is a ~48 s mean and the reading
// only changes at that period.
#ifndef CLOTHWIND_SENSORS_FINE_OFFSET_RECORD_H_
#define CLOTHWIND_SENSORS_FINE_OFFSET_RECORD_H_

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sensors/wind_reading.h"

namespace clothwind::sensors {

constexpr uint16_t kFineOffsetVendorId = 0x1941;
constexpr uint16_t kFineOffsetProductId = 0x8021;
constexpr size_t kFineOffsetChunkSize = 32;        // bytes per USB memory read
constexpr size_t kFineOffsetFixedBlockSize = 256;  // 0x0000..0x00FF
constexpr size_t kFineOffsetCurrentPosOffset = 0x1E;
constexpr uint16_t kFineOffsetDataStart = 0x0100;
constexpr size_t kFineOffsetRecordSize = 16;
constexpr double kFineOffsetSensorPeriod = 48.0;   // outdoor sensor transmit period [s]

// A decoded history/current record.
struct FineOffsetRecord {
  int delay_minutes = 0;
  double wind_average = kNaN;  // [m/s], NaN when the station has no value
  double wind_gust = kNaN;     // [m/s]
  int direction_index = -1;    // 0..15 (N, NNE, ...), -1 when flagged invalid
  bool lost_contact = false;   // status bit 6: no data from the outdoor sensor
  bool rain_overflow = false;  // status bit 7
  double temperature_out = kNaN;  // [deg C]
  double pressure_abs = kNaN;     // [hPa]
  int humidity_out = -1;          // [%], -1 when absent
};

// Address of the current record from the first 32 bytes (or more) of the fixed block.
// Inputs:
//   fixed  fixed-block bytes starting at address 0x0000 (at least 0x20)
// Outputs:
//   address  the current record's address (>= 0x0100)
//   error    why it failed
// Returns false when the block is too short or the address is outside the record area.
bool FineOffsetCurrentAddress(const std::vector<uint8_t>& fixed, uint16_t* address, std::string* error);

// Decodes one record.
// Inputs:
//   bytes  at least 16 record bytes
// Outputs:
//   record  the decoded values
//   error   why it failed
// Returns false when fewer than 16 bytes are given.
bool ParseFineOffsetRecord(const std::vector<uint8_t>& bytes, FineOffsetRecord* record, std::string* error);

// Converts a record to a wind reading: speed = average, gust, direction as a compass bearing
// (north-aligned station: AngleReference::kEarth), none in calm air (average 0). valid is false
// when contact was lost or the average is missing.
// Inputs:
//   record  decoded record
// Returns the reading (source "fine_offset").
WindReading FineOffsetToReading(const FineOffsetRecord& record);

// Parses a record given as hex text (how RawSentence carries binary records): 32 hex digits
// (WH1080) or 40 (WH3080).
// Inputs:
//   hex  hex digits, upper or lower case, optional spaces
// Returns kOk with the reading, or kMalformed naming the problem (another length among them).
ParseResult ParseFineOffsetHex(const std::string& hex);

// The 8-byte read command the station expects (sent as a HID SET_REPORT control transfer):
// A1 addr_hi addr_lo 20 A1 addr_hi addr_lo 20.
// Inputs:
//   address  memory address to read 32 bytes from
std::array<uint8_t, 8> FineOffsetReadCommand(uint16_t address);

// Hex text of bytes ("0A1B..."), upper case, no separators.
std::string HexEncode(const std::vector<uint8_t>& bytes);

// Bytes of hex text; spaces ignored.
// Outputs:
//   bytes  decoded bytes
// Returns false on an odd count or a non-hex character.
bool HexDecode(const std::string& hex, std::vector<uint8_t>* bytes);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_FINE_OFFSET_RECORD_H_
