#include "sensors/fine_offset_record.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>

namespace clothwind::sensors {
namespace {

// Sign-magnitude 16-bit value (bit 15 = sign), as the station stores temperatures.
double SignMagnitude16(uint8_t lo, uint8_t hi) {
  const int raw = lo | (hi << 8);
  if (raw == 0xFFFF) return kNaN;
  const int mag = raw & 0x7FFF;
  return (raw & 0x8000) ? -mag : mag;
}

}  // namespace

bool FineOffsetCurrentAddress(const std::vector<uint8_t>& fixed, uint16_t* address, std::string* error) {
  if (fixed.size() < kFineOffsetCurrentPosOffset + 2) {
    *error = "fine_offset: fixed block has " + std::to_string(fixed.size()) + " bytes, need at least 32";
    return false;
  }
  const unsigned a = fixed[kFineOffsetCurrentPosOffset] | (fixed[kFineOffsetCurrentPosOffset + 1] << 8);
  if (a < kFineOffsetDataStart || a > 0x10000 - kFineOffsetRecordSize) {
    char msg[96];
    std::snprintf(msg, sizeof(msg), "fine_offset: current record address 0x%04X outside 0x0100..0xFFF0", a);
    *error = msg;
    return false;
  }
  *address = static_cast<uint16_t>(a);
  return true;
}

bool ParseFineOffsetRecord(const std::vector<uint8_t>& b, FineOffsetRecord* r, std::string* error) {
  if (b.size() < kFineOffsetRecordSize) {
    *error = "fine_offset: record has " + std::to_string(b.size()) + " bytes, expected 16 (or 20)";
    return false;
  }
  *r = FineOffsetRecord();
  r->delay_minutes = b[0];
  r->humidity_out = b[4] == 0xFF ? -1 : b[4];
  const double t = SignMagnitude16(b[5], b[6]);
  r->temperature_out = t * 0.1;
  const int p = b[7] | (b[8] << 8);
  r->pressure_abs = p == 0xFFFF ? kNaN : p * 0.1;
  // 12-bit speeds: the low byte plus a nibble of byte 11; all twelve bits set (0xFFF) mean no
  // value, as weewx's fousb reads them. (pywws takes a low byte 0xFF alone as no value; here that
  // is 25.5 or 51.1 m/s, a gale. Bytes from a station whose outdoor sensor is unplugged would
  // settle which is right.)
  const int average = b[9] | ((b[11] & 0x0F) << 8), gust = b[10] | ((b[11] & 0xF0) << 4);
  if (average != 0xFFF) r->wind_average = average * 0.1;
  if (gust != 0xFFF) r->wind_gust = gust * 0.1;
  r->direction_index = (b[12] & 0x80) ? -1 : (b[12] & 0x0F);
  if ((b[12] & 0x80) == 0 && b[12] > 15) r->direction_index = -1;
  r->lost_contact = (b[15] & 0x40) != 0;
  r->rain_overflow = (b[15] & 0x80) != 0;
  return true;
}

WindReading FineOffsetToReading(const FineOffsetRecord& r) {
  WindReading w;
  w.source = "fine_offset";
  w.relative = false;
  w.valid = !r.lost_contact && std::isfinite(r.wind_average);
  // A void reading (lost contact, no average) keeps what is possible of its fields: a lost
  // sensor's average of 389 m/s reached anemometer/wind's subscribers (MWV's void filler is
  // dropped the same way). A valid one's are checked by the decoder, which refuses it whole.
  auto possible = [](double v) { return v <= kMaxPlausibleWindSpeed ? v : std::numeric_limits<double>::quiet_NaN(); };
  w.speed = w.valid ? r.wind_average : possible(r.wind_average);
  w.gust = w.valid ? r.wind_gust : possible(r.wind_gust);
  // The vane keeps pointing somewhere in calm air; like other Fine Offset software, report no
  // direction when the average is zero.
  if (r.direction_index >= 0 && !(r.wind_average == 0.0)) {
    w.from_angle_deg = r.direction_index * 22.5;
    w.reference = AngleReference::kEarth;
  }
  w.status = r.lost_contact                      ? "lost contact with outdoor sensor"
             : !std::isfinite(r.wind_average) ? "no wind average"
             : r.direction_index < 0          ? "direction invalid"
                                              : "ok";
  return w;
}

ParseResult ParseFineOffsetHex(const std::string& hex) {
  ParseResult res;
  std::vector<uint8_t> bytes;
  if (!HexDecode(hex, &bytes)) {
    res.error = "fine_offset: record is not hex text: '" + hex.substr(0, 40) + "'";
    return res;
  }
  // One whole record: a longer one was cut to its first 16 bytes without a word, and two records
  // run together read as the first, the second lost.
  if (bytes.size() != kFineOffsetRecordSize && bytes.size() != 20) {
    res.error = "fine_offset: record has " + std::to_string(bytes.size()) +
                " bytes, expected 16 (WH1080) or 20 (WH3080): one record per message";
    return res;
  }
  FineOffsetRecord rec;
  if (!ParseFineOffsetRecord(bytes, &rec, &res.error)) return res;
  res.reading = FineOffsetToReading(rec);
  res.status = ParseStatus::kOk;
  return res;
}

std::array<uint8_t, 8> FineOffsetReadCommand(uint16_t address) {
  const uint8_t hi = address >> 8, lo = address & 0xFF;
  return {0xA1, hi, lo, 0x20, 0xA1, hi, lo, 0x20};
}

std::string HexEncode(const std::vector<uint8_t>& bytes) {
  static const char* kDigits = "0123456789ABCDEF";
  std::string s;
  s.reserve(bytes.size() * 2);
  for (uint8_t b : bytes) {
    s.push_back(kDigits[b >> 4]);
    s.push_back(kDigits[b & 0x0F]);
  }
  return s;
}

bool HexDecode(const std::string& hex, std::vector<uint8_t>* bytes) {
  bytes->clear();
  int pending = -1;
  for (char c : hex) {
    if (c == ' ') continue;
    if (!std::isxdigit(static_cast<unsigned char>(c))) return false;
    const int v = std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : (std::toupper(c) - 'A' + 10);
    if (pending < 0) {
      pending = v;
    } else {
      bytes->push_back(static_cast<uint8_t>((pending << 4) | v));
      pending = -1;
    }
  }
  return pending < 0 && !bytes->empty();
}

}  // namespace clothwind::sensors
