#include "sensors/nmea.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "common/formatted.h"
#include "sensors/gill_windsonic.h"
#include "sensors/protocol_fields.h"

namespace clothwind::sensors {
namespace {

ParseResult Fail(ParseStatus s, std::string msg) {
  ParseResult r;
  r.status = s;
  r.error = std::move(msg);
  return r;
}

// Half a unit of a number's last printed digit: "12" 0.5, "6.17" 0.005 (the rounding it may carry).
double HalfLastDigit(const std::string& field) {
  const std::string t = field.substr(0, field.find_first_of("eE"));
  const size_t dot = t.find('.');
  const size_t decimals = dot == std::string::npos ? 0 : t.size() - dot - 1;
  return 0.5 * std::pow(10.0, -static_cast<double>(decimals));
}

bool NmeaSpeedUnit(const std::string& f, SpeedUnit* unit) {
  if (f == "M") *unit = SpeedUnit::kMetresPerSecond;
  else if (f == "N") *unit = SpeedUnit::kKnots;
  else if (f == "K") *unit = SpeedUnit::kKilometresPerHour;
  else if (f == "S") *unit = SpeedUnit::kMilesPerHour;  // statute miles per hour
  // Gill's WindSonic and WindObserver in NMEA mode write their own unit letters, P (mph) and F
  // (ft/min), when set to those units (WindSonic manual 9.4: "as described in Section 9.1").
  else if (f == "P") *unit = SpeedUnit::kMilesPerHour;
  else if (f == "F") *unit = SpeedUnit::kFeetPerMinute;
  else return false;
  return true;
}

// XDR's speed units: the standard's M, N, K and S only. Gill's P and F are MWV's (its manual);
// in an XDR, F is a temperature's Fahrenheit, and a WINDCHILL of 40 F was read as a wind speed of
// 40 ft/min, over the sentence's own WSPD.
bool XdrSpeedUnit(const std::string& f, SpeedUnit* unit) {
  return (f == "M" || f == "N" || f == "K" || f == "S") && NmeaSpeedUnit(f, unit);
}

ParseResult ParseMwv(const NmeaSentence& s) {
  // $--MWV,<angle>,<R|T>,<speed>,<K|M|N|S>,<A|V>
  const std::string where = s.talker + "MWV";
  if (s.fields.size() < 5)
    return Fail(ParseStatus::kMalformed, where + ": expected 5 fields (angle,ref,speed,unit,status), got " +
                                             std::to_string(s.fields.size()));
  ParseResult r;
  WindReading& w = r.reading;
  w.source = "nmea_mwv";
  const std::string& status = s.fields[4];
  // A Gill WindSonic in its NMEA mode with status codes sends its two-digit code here instead.
  const bool gill_code = status.size() == 2 && std::isxdigit(static_cast<unsigned char>(status[0])) &&
                         std::isxdigit(static_cast<unsigned char>(status[1]));
  if (status != "A" && status != "V" && !gill_code)
    return Fail(ParseStatus::kMalformed,
                where + " field 5 (status): expected A, V or a two-digit Gill code, got '" + status + "'");
  if (gill_code) {
    bool ok = false;
    w.status = status + " " + GillStatusText(status, &ok);
    w.valid = ok;
  } else {
    w.valid = status == "A";
    w.status = status;
  }
  const std::string& ref = s.fields[1];
  if (!w.valid) {
    // A void reading says what the instrument says in its status, whatever its fields hold: empty
    // ("$IIMWV,,,,,V"), or a failed measurement's filler (a WindSonic with status codes pads them
    // with 9s, "999,R,999.99,M,04", as its own format does). It keeps the values it can read and
    // drops the rest (it was refused as malformed, naming the angle, and the failure went unsaid).
    double angle = kNaN, speed = kNaN;
    std::string ignored;
    SpeedUnit unit;
    if (ref == "R" || ref == "T") {
      w.relative = ref == "R";
      if (ParseOptionalNumber(s.fields[0], &angle, &ignored) && angle >= 0.0 && angle <= 360.0) {
        w.from_angle_deg = angle;
        w.reference = AngleReference::kInstrument;
      }
    }
    if (ParseOptionalNumber(s.fields[2], &speed, &ignored) && speed >= 0.0 && NmeaSpeedUnit(s.fields[3], &unit) &&
        SpeedToMetresPerSecond(speed, unit) <= kMaxPlausibleWindSpeed)
      w.speed = SpeedToMetresPerSecond(speed, unit);
    r.status = ParseStatus::kOk;
    return r;
  }
  if (ref != "R" && ref != "T")
    return Fail(ParseStatus::kMalformed, where + " field 2 (reference): expected R or T, got '" + ref + "'");
  w.relative = ref == "R";
  double angle = kNaN, speed = kNaN;
  std::string err;
  if (!ParseOptionalNumber(s.fields[0], &angle, &err))
    return Fail(ParseStatus::kMalformed, where + " field 1 (angle): " + err);
  if (!ParseOptionalNumber(s.fields[2], &speed, &err))
    return Fail(ParseStatus::kMalformed, where + " field 3 (speed): " + err);
  if (std::isfinite(angle) && (angle < 0.0 || angle > 360.0))
    return Fail(ParseStatus::kMalformed, where + " field 1 (angle): expected 0..360 deg, got " + s.fields[0]);
  if (std::isfinite(speed) && speed < 0.0)
    return Fail(ParseStatus::kMalformed, where + " field 3 (speed): expected >= 0, got " + s.fields[2]);
  SpeedUnit unit;
  if (std::isfinite(speed) && !NmeaSpeedUnit(s.fields[3], &unit))
    return Fail(ParseStatus::kMalformed,
                where + " field 4 (unit): expected K, M, N or S (or Gill's P, F), got '" + s.fields[3] + "'");
  if (std::isfinite(speed)) w.speed = SpeedToMetresPerSecond(speed, unit);
  // Calm air has no direction (a WindSonic leaves it empty below 0.05 m/s); a speed it must have.
  if (w.valid && !std::isfinite(speed))
    return Fail(ParseStatus::kMalformed, where + " field 3 (speed): empty with status " + status);
  w.from_angle_deg = angle;
  w.reference = std::isfinite(angle) ? AngleReference::kInstrument : AngleReference::kNone;
  r.status = ParseStatus::kOk;
  return r;
}

ParseResult ParseMwd(const NmeaSentence& s) {
  // $--MWD,<dir true>,T,<dir magnetic>,M,<speed kn>,N,<speed m/s>,M
  const std::string where = s.talker + "MWD";
  if (s.fields.size() < 8)
    return Fail(ParseStatus::kMalformed, where + ": expected 8 fields, got " + std::to_string(s.fields.size()));
  const char* expected_units[] = {"T", "M", "N", "M"};
  for (int i = 0; i < 4; ++i) {
    const std::string& u = s.fields[2 * i + 1];
    if (!u.empty() && u != expected_units[i])
      return Fail(ParseStatus::kMalformed, where + " field " + std::to_string(2 * i + 2) + ": expected '" +
                                               expected_units[i] + "', got '" + u + "'");
  }
  double v[4];
  std::string err;
  for (int i = 0; i < 4; ++i)
    if (!ParseOptionalNumber(s.fields[2 * i], &v[i], &err))
      return Fail(ParseStatus::kMalformed, where + " field " + std::to_string(2 * i + 1) + ": " + err);
  ParseResult r;
  WindReading& w = r.reading;
  w.source = "nmea_mwd";
  w.relative = false;
  // Prefer the true bearing: a magnetic one needs the local declination (kMagnetic: the node's
  // ~magnetic_declination, without which it gets no direction).
  if (std::isfinite(v[0])) {
    w.from_angle_deg = v[0];
    w.status = "true";
  } else if (std::isfinite(v[1])) {
    w.from_angle_deg = v[1];
    w.status = "magnetic";
  }
  if (std::isfinite(w.from_angle_deg) && (w.from_angle_deg < 0.0 || w.from_angle_deg > 360.0)) {
    const bool true_bearing = w.status == "true";
    return Fail(ParseStatus::kMalformed, where + (true_bearing ? " field 1 (true direction)" : " field 3 (magnetic direction)") +
                                             ": expected 0..360 deg, got " + s.fields[true_bearing ? 0 : 2]);
  }
  w.reference = !std::isfinite(w.from_angle_deg) ? AngleReference::kNone
                : w.status == "true"              ? AngleReference::kEarth
                                                  : AngleReference::kMagnetic;
  if (std::isfinite(v[3])) w.speed = v[3];
  else if (std::isfinite(v[2])) w.speed = SpeedToMetresPerSecond(v[2], SpeedUnit::kKnots);
  else return Fail(ParseStatus::kMalformed, where + ": neither knots (field 5) nor m/s (field 7) speed given");
  if (w.speed < 0.0) {
    const bool metres = std::isfinite(v[3]);
    return Fail(ParseStatus::kMalformed, where + (metres ? " field 7 (speed, m/s)" : " field 5 (speed, knots)") +
                                             ": expected >= 0, got " + s.fields[metres ? 6 : 4]);
  }
  // Both given: they must say one speed, within their rounding (a corrupt field whose checksum
  // still matched, or a sentence without one, read "20 N, 1 M" as 1 m/s).
  if (std::isfinite(v[2]) && std::isfinite(v[3])) {
    const double from_knots = SpeedToMetresPerSecond(v[2], SpeedUnit::kKnots);
    // Within each field's rounding (half its last printed digit: whole numbers differ by up to
    // 0.76 m/s, "12 N, 6 M"), plus 1 % for instruments that convert before rounding.
    const double rounding = SpeedToMetresPerSecond(HalfLastDigit(s.fields[4]), SpeedUnit::kKnots) +
                            HalfLastDigit(s.fields[6]);
    if (std::abs(from_knots - v[3]) > rounding + 0.01 * std::max(from_knots, v[3])) {
      return Fail(ParseStatus::kMalformed,
                  where + Formatted(": field 5 (%s kn, %.3g m/s) and field 7 (%s m/s) disagree", s.fields[4].c_str(),
                                    from_knots, s.fields[6].c_str()));
    }
  }
  r.status = ParseStatus::kOk;
  return r;
}

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

ParseResult ParseXdr(const NmeaSentence& s) {
  // $--XDR,<type>,<value>,<units>,<name>[,<type>,<value>,<units>,<name>...]
  // There is no standard wind transducer type, so quadruplets are recognised by their name:
  // WIND/WSPD/WDIR/WGUST style names; direction needs units D (degrees), speeds M, N or K.
  const std::string where = s.talker + "XDR";
  if (s.fields.empty() || s.fields.size() % 4 != 0)
    return Fail(ParseStatus::kMalformed,
                where + ": expected quadruplets (type,value,units,name), got " + std::to_string(s.fields.size()) +
                    " fields");
  ParseResult r;
  WindReading& w = r.reading;
  w.source = "nmea_xdr";
  bool any = false;
  // One value of each kind is read, where a station may send several (WSPD and WSPD_AVG, WINDSPEED
  // and WINDSPEEDMAX, WDIR and WDIR_AVG): the plain name's, else the first's. (The last used to
  // overwrite the others without a word.)
  struct Chosen {
    bool plain = false, set = false;
  } direction, speed, gust;
  auto take = [](Chosen* c, const std::string& name, std::initializer_list<const char*> plain_names) {
    bool plain = false;
    for (const char* p : plain_names) plain = plain || name == p;
    if (c->set && (c->plain || !plain)) return false;
    c->set = true;
    c->plain = plain;
    return true;
  };
  for (size_t q = 0; q < s.fields.size(); q += 4) {
    const std::string name = Upper(s.fields[q + 3]);
    const bool windish = name.find("WIND") != std::string::npos || name.rfind("WSPD", 0) == 0 ||
                         name.rfind("WDIR", 0) == 0 || name.rfind("WGUST", 0) == 0;
    if (!windish) continue;
    double value;
    std::string err;
    if (!ParseOptionalNumber(s.fields[q + 1], &value, &err))
      return Fail(ParseStatus::kMalformed,
                  where + " quadruplet '" + s.fields[q + 3] + "' field " + std::to_string(q + 2) + ": " + err);
    if (!std::isfinite(value)) continue;
    const std::string& units = s.fields[q + 2];
    // A name like WINDCHILL in degrees Celsius is no wind quantity: skipped, as other XDR
    // quadruplets are, where it used to void the sentence's wind. (WSPD, WGUST and names with
    // DIR or SPEED are wind whatever their units, which are then checked.)
    SpeedUnit unused;
    const bool surely_wind = name.rfind("WSPD", 0) == 0 || name.rfind("WGUST", 0) == 0 ||
                             name.find("DIR") != std::string::npos || name.find("SPEED") != std::string::npos;
    if (!surely_wind && units != "D" && !XdrSpeedUnit(units, &unused)) continue;
    if (name.find("DIR") != std::string::npos) {
      if (units != "D")
        return Fail(ParseStatus::kMalformed, where + " quadruplet '" + s.fields[q + 3] +
                                                 "': direction units expected D (degrees), got '" + units + "'");
      // As MWV's angle: named here with its field (ImplausibleWindReason refused it later, unplaced).
      if (value < 0.0 || value > 360.0)
        return Fail(ParseStatus::kMalformed, where + " quadruplet '" + s.fields[q + 3] + "' field " +
                                                 std::to_string(q + 2) + " (direction): expected 0..360 deg, got " +
                                                 s.fields[q + 1]);
      if (take(&direction, name, {"WDIR", "WINDDIR", "WIND_DIR", "WINDDIRECTION", "WIND_DIRECTION"})) {
        w.from_angle_deg = value;
        w.reference = AngleReference::kInstrument;
      }
      any = true;
    } else {
      SpeedUnit unit;
      if (!XdrSpeedUnit(units, &unit))
        return Fail(ParseStatus::kMalformed, where + " quadruplet '" + s.fields[q + 3] +
                                                 "': speed units expected M, N, K or S, got '" + units + "'");
      if (value < 0.0)
        return Fail(ParseStatus::kMalformed, where + " quadruplet '" + s.fields[q + 3] + "' field " +
                                                 std::to_string(q + 2) + " (speed): expected >= 0, got " +
                                                 s.fields[q + 1]);
      if (name.find("GUST") != std::string::npos) {
        if (take(&gust, name, {"WGUST", "WINDGUST", "WIND_GUST", "GUST"})) w.gust = SpeedToMetresPerSecond(value, unit);
      } else if (take(&speed, name, {"WSPD", "WINDSPEED", "WIND_SPEED", "WIND"})) {
        w.speed = SpeedToMetresPerSecond(value, unit);
      }
      any = true;
    }
  }
  if (!any) {
    r.status = ParseStatus::kNotWind;
    return r;
  }
  if (!std::isfinite(w.speed))
    return Fail(ParseStatus::kMalformed, where + ": wind quadruplets but no wind speed");
  r.status = ParseStatus::kOk;
  return r;
}

}  // namespace

uint8_t NmeaChecksum(const std::string& body) {
  uint8_t c = 0;
  for (unsigned char ch : body) c ^= ch;
  return c;
}

std::string WithNmeaChecksum(const std::string& body) {
  char hex[4];
  std::snprintf(hex, sizeof(hex), "%02X", NmeaChecksum(body));
  return "$" + body + "*" + hex;
}

bool SplitNmeaSentence(const std::string& raw_record, NmeaSentence* out, ParseResult* error) {
  // Trailing blanks are line noise, as the Gill parser treats them: "...*39 " was refused as a
  // checksum of three characters.
  const std::string record = raw_record.substr(0, raw_record.find_last_not_of(" \t") + 1);
  auto fail = [&](ParseStatus s, const std::string& m) {
    *error = Fail(s, "NMEA: " + m);
    return false;
  };
  if (record.empty() || (record[0] != '$' && record[0] != '!')) return fail(ParseStatus::kMalformed, "expected '$' at start");
  for (unsigned char c : record)
    if (c < 0x20 || c > 0x7E) return fail(ParseStatus::kMalformed, "non-printable byte in sentence");
  std::string body;
  const size_t star = record.find('*');
  out->has_checksum = star != std::string::npos;
  if (out->has_checksum) {
    body = record.substr(1, star - 1);
    const std::string hex = record.substr(star + 1);
    if (hex.size() != 2 || !std::isxdigit(static_cast<unsigned char>(hex[0])) ||
        !std::isxdigit(static_cast<unsigned char>(hex[1])))
      return fail(ParseStatus::kMalformed, "expected two hex digits after '*', got '" + hex + "'");
    const unsigned expected = static_cast<unsigned>(std::strtoul(hex.c_str(), nullptr, 16));
    const unsigned actual = NmeaChecksum(body);
    if (expected != actual) {
      char msg[96];
      std::snprintf(msg, sizeof(msg), "checksum mismatch: sentence says %02X, computed %02X", expected, actual);
      return fail(ParseStatus::kChecksumError, msg);
    }
  } else {
    body = record.substr(1);
  }
  const size_t comma = body.find(',');
  const std::string address = body.substr(0, comma);
  if (address.size() < 4 || address.size() > 6)
    return fail(ParseStatus::kMalformed, "address field '" + address + "' is not <talker><type>");
  for (char c : address)
    if (!std::isalnum(static_cast<unsigned char>(c)))
      return fail(ParseStatus::kMalformed, "address field '" + address + "' is not alphanumeric");
  if (address[0] == 'P') {
    out->talker = "P";
    out->type = address.substr(1);
  } else {
    out->talker = address.substr(0, 2);
    out->type = address.substr(2);
  }
  out->fields.clear();
  if (comma != std::string::npos) out->fields = SplitCommas(body.substr(comma + 1), false);
  return true;
}

ParseResult ParseNmea(const std::string& record) {
  NmeaSentence s;
  ParseResult r;
  if (!SplitNmeaSentence(record, &s, &r)) return r;
  if (s.type == "MWV") return ParseMwv(s);
  if (s.type == "MWD") return ParseMwd(s);
  if (s.type == "XDR") return ParseXdr(s);
  r.status = ParseStatus::kNotWind;
  r.error = "NMEA " + s.talker + s.type + " carries no wind";
  return r;
}

}  // namespace clothwind::sensors
