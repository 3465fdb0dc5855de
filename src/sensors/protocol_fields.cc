#include "sensors/protocol_fields.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <utility>

namespace clothwind::sensors {

std::string TrimSpaces(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCommas(const std::string& s, bool trim_spaces) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t next = s.find(',', start);
    std::string field = s.substr(start, next == std::string::npos ? std::string::npos : next - start);
    out.push_back(trim_spaces ? TrimSpaces(field) : std::move(field));
    if (next == std::string::npos) break;
    start = next + 1;
  }
  return out;
}

bool ParseOptionalNumber(const std::string& field, double* value, std::string* error) {
  const std::string t = TrimSpaces(field);
  if (t.empty()) {
    *value = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  // strtod accepts "inf", "nan" and hex floats; instruments send none of those.
  for (char c : t) {
    if (!((c >= '0' && c <= '9') || c == '.' || c == '-' || c == '+' || c == 'e' || c == 'E')) {
      *error = "expected a number, got '" + field + "'";
      return false;
    }
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end != t.c_str() + t.size() || errno != 0 || !std::isfinite(v)) {
    *error = "expected a number, got '" + field + "'";
    return false;
  }
  *value = v;
  return true;
}

}  // namespace clothwind::sensors
