#include "sensors/gill_windsonic.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "sensors/protocol_fields.h"

namespace clothwind::sensors {
namespace {

ParseResult Fail(ParseStatus s, std::string msg) {
  ParseResult r;
  r.status = s;
  r.error = "Gill: " + std::move(msg);
  return r;
}

bool GillSpeedUnit(const std::string& f, SpeedUnit* unit) {
  if (f == "M") *unit = SpeedUnit::kMetresPerSecond;
  else if (f == "N") *unit = SpeedUnit::kKnots;
  else if (f == "P") *unit = SpeedUnit::kMilesPerHour;
  else if (f == "K") *unit = SpeedUnit::kKilometresPerHour;
  else if (f == "F") *unit = SpeedUnit::kFeetPerMinute;
  else return false;
  return true;
}

// Below this speed [m/s] a WindSonic computes no direction (its K setting, 0.05 m/s by default):
// polar records leave it empty in variable-field mode and freeze the last one in fixed-field mode
// (manual 1405-PS-0019, 9.1), and a UV pair that small points anywhere.
constexpr double kGillCalm = 0.05;

}  // namespace

uint8_t GillChecksum(const std::string& body) {
  uint8_t c = 0;
  for (unsigned char ch : body) c ^= ch;
  return c;
}

std::string FrameGillRecord(const std::string& body) {
  char hex[4];
  std::snprintf(hex, sizeof(hex), "%02X", GillChecksum(body));
  return std::string(1, kGillStx) + body + kGillEtx + hex;
}

std::string GillStatusText(const std::string& code, bool* valid) {
  *valid = false;
  if (code == "00") { *valid = true; return "ok"; }
  if (code == "51") { *valid = true; return "measurement average building"; }
  if (code == "60") { *valid = true; return "ok, heating enabled"; }
  if (code == "01") return "axis 1 failed";
  if (code == "02") return "axis 2 failed";
  if (code == "04") return "axis 1 and 2 failed";
  if (code == "08") return "NVM checksum error";
  if (code == "09") return "ROM checksum error";
  if (code == "0A" || code == "10") return "system gain at maximum";
  return "unknown status";
}

ParseResult ParseGillWindSonic(const std::string& record) {
  if (record.empty() || record[0] != kGillStx) return Fail(ParseStatus::kMalformed, "expected STX at start");
  const size_t etx = record.find(kGillEtx);
  if (etx == std::string::npos) return Fail(ParseStatus::kMalformed, "no ETX (truncated record)");
  const std::string body = record.substr(1, etx - 1);
  const std::string hex = TrimSpaces(record.substr(etx + 1));
  if (hex.size() != 2 || !std::isxdigit(static_cast<unsigned char>(hex[0])) ||
      !std::isxdigit(static_cast<unsigned char>(hex[1])))
    return Fail(ParseStatus::kMalformed, "expected two hex checksum digits after ETX, got '" + hex + "'");
  for (unsigned char c : body)
    if (c < 0x20 || c > 0x7E) return Fail(ParseStatus::kMalformed, "non-printable byte between STX and ETX");
  const unsigned expected = static_cast<unsigned>(std::strtoul(hex.c_str(), nullptr, 16));
  const unsigned actual = GillChecksum(body);
  if (expected != actual) {
    char msg[96];
    std::snprintf(msg, sizeof(msg), "checksum mismatch: record says %02X, computed %02X", expected, actual);
    return Fail(ParseStatus::kChecksumError, msg);
  }
  std::vector<std::string> f = SplitCommas(body, true);
  if (!f.empty() && f.back().empty()) f.pop_back();  // the trailing comma before ETX
  // node, a, b, units, [speed of sound, temperature on other Gill models,] status
  if (f.size() < 5) return Fail(ParseStatus::kMalformed, "expected at least 5 fields, got " + std::to_string(f.size()));
  if (f[0].size() != 1 || !std::isupper(static_cast<unsigned char>(f[0][0])))
    return Fail(ParseStatus::kMalformed, "field 1 (node address): expected a letter A-Z, got '" + f[0] + "'");
  SpeedUnit unit;
  if (!GillSpeedUnit(f[3], &unit))
    return Fail(ParseStatus::kMalformed, "field 4 (units): expected M, N, P, K or F, got '" + f[3] + "'");
  ParseResult r;
  WindReading& w = r.reading;
  w.source = "gill";
  w.relative = false;  // a fixed sonic measures the true wind in its own frame
  const std::string& status = f.back();
  bool status_ok = false;
  w.status = status + " " + GillStatusText(status, &status_ok);
  w.valid = status_ok;
  // A failed measurement (e.g. 04, a blocked path) pads its fields with 9s in fixed-field mode:
  // a void reading, not a malformed record, so diagnostics can say what the instrument said.
  if (!status_ok) {
    r.status = ParseStatus::kOk;
    return r;
  }
  double a, b;
  std::string err;
  if (!ParseOptionalNumber(f[1], &a, &err)) return Fail(ParseStatus::kMalformed, "field 2: " + err);
  if (!ParseOptionalNumber(f[2], &b, &err)) return Fail(ParseStatus::kMalformed, "field 3: " + err);
  // UV signs both components; polar signs neither. A signed field 2, or an empty one beside a
  // signed field 3, is UV: "Q,,+002.00,M,00" (U lost) read as polar, 2 m/s with no direction,
  // under status OK. A polar direction beside a signed speed stays polar, its negative speed
  // refused ("Q,045,-002.00" read as UV gave 45 m/s).
  const auto signed_field = [](const std::string& s) { return !s.empty() && (s[0] == '+' || s[0] == '-'); };
  const bool uv = signed_field(f[1]) || (f[1].empty() && signed_field(f[2]));
  if (uv) {
    if (!std::isfinite(a) || !std::isfinite(b))
      return Fail(ParseStatus::kMalformed, std::string("UV: field ") + (std::isfinite(a) ? "3 (V)" : "2 (U)") +
                                               " empty, expected a signed speed");
    const double u = SpeedToMetresPerSecond(a, unit), v = SpeedToMetresPerSecond(b, unit);
    w.speed = std::hypot(u, v);
    if (w.speed >= kGillCalm) {
      // velocity direction atan2(v, u) = pi - from  =>  from = pi - atan2(v, u), in [0, 360)
      double from = 180.0 - std::atan2(v, u) * 180.0 / M_PI;
      from = std::fmod(from + 360.0, 360.0);
      w.from_angle_deg = from;
      w.reference = AngleReference::kInstrument;
    }
  } else {
    // Whole degrees: the WindObserver's tunnel record, "A,001.59,1,M,00," (speed, polarity), read
    // as polar gave a wind from 1.59 deg at 1 m/s.
    const bool whole = f[1].find_first_not_of("0123456789") == std::string::npos;
    if (std::isfinite(a) && (!whole || a > 360.0))
      return Fail(ParseStatus::kMalformed, "field 2 (direction): expected whole degrees 0..360, got '" + f[1] + "'");
    if (!std::isfinite(b)) {
      if (status_ok) return Fail(ParseStatus::kMalformed, "field 3 (speed) empty with status " + status);
    } else {
      if (b < 0.0) return Fail(ParseStatus::kMalformed, "field 3 (speed): expected >= 0, got '" + f[2] + "'");
      w.speed = SpeedToMetresPerSecond(b, unit);
    }
    // Empty (NaN) in calm air; in fixed-field mode the last direction, frozen ("Q,133,000.02,M,00,"),
    // is no direction either.
    if (!(w.speed >= kGillCalm)) a = std::numeric_limits<double>::quiet_NaN();
    w.from_angle_deg = a;
    w.reference = std::isfinite(a) ? AngleReference::kInstrument : AngleReference::kNone;
  }
  r.status = ParseStatus::kOk;
  return r;
}

}  // namespace clothwind::sensors
