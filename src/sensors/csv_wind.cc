#include "sensors/csv_wind.h"

#include <cctype>
#include <cmath>
#include <vector>

#include "sensors/protocol_fields.h"

namespace clothwind::sensors {
namespace {

bool IsHeader(const std::string& record) {
  std::string t = TrimSpaces(record);
  for (char& c : t) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return t.rfind("speed", 0) == 0 && t.find(',') != std::string::npos;
}

}  // namespace

bool LooksLikeCsvWind(const std::string& record) {
  if (IsHeader(record)) return true;
  const std::vector<std::string> f = SplitCommas(record, true);
  if (f.size() < 2 || f.size() > 3 || f[0].empty()) return false;
  for (char c : record) {
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+' || c == 'e' ||
          c == 'E' || c == ',' || c == ' ' || c == '\t'))
      return false;
  }
  return true;
}

ParseResult ParseCsvWind(const std::string& record) {
  ParseResult r;
  if (IsHeader(record)) {
    r.status = ParseStatus::kNotWind;
    r.error = "CSV header line";
    return r;
  }
  const std::vector<std::string> f = SplitCommas(record, true);
  if (f.size() < 2 || f.size() > 3) {
    r.error = "CSV: expected 'speed,direction[,gust]', got " + std::to_string(f.size()) + " fields";
    return r;
  }
  static const char* kNames[] = {"speed", "direction", "gust"};
  double v[3] = {kNaN, kNaN, kNaN};
  for (size_t i = 0; i < f.size(); ++i) {
    std::string err;
    if (!ParseOptionalNumber(f[i], &v[i], &err)) {
      r.error = "CSV field " + std::to_string(i + 1) + " (" + kNames[i] + "): " + err;
      return r;
    }
  }
  if (!std::isfinite(v[0]) || v[0] < 0.0) {
    r.error = "CSV field 1 (speed): expected a number >= 0 [m/s], got '" + f[0] + "'";
    return r;
  }
  if (std::isfinite(v[1]) && (v[1] < 0.0 || v[1] > 360.0)) {
    r.error = "CSV field 2 (direction): expected 0..360 deg, got '" + f[1] + "'";
    return r;
  }
  if (std::isfinite(v[2]) && v[2] < 0.0) {
    r.error = "CSV field 3 (gust): expected >= 0 [m/s], got '" + f[2] + "'";
    return r;
  }
  WindReading& w = r.reading;
  w.source = "csv";
  w.speed = v[0];
  w.from_angle_deg = v[1];
  w.reference = std::isfinite(v[1]) ? AngleReference::kInstrument : AngleReference::kNone;
  w.gust = v[2];
  r.status = ParseStatus::kOk;
  return r;
}

}  // namespace clothwind::sensors
