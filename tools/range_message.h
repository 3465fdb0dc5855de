// CLI11's range validators print their bounds with std::to_string, so an option with no upper
// bound said "Value 0 not in range 0.000000 to 17976931348623157081...(309 digits).000000", and a
// positive one refused 0 as "not in range 0.000000" (its bound is the smallest double > 0).
#ifndef CLOTHWIND_TOOLS_RANGE_MESSAGE_H_
#define CLOTHWIND_TOOLS_RANGE_MESSAGE_H_

#include <cstdlib>
#include <regex>
#include <string>

namespace clothwind::tools {

// "2.500000" -> "2.5", "0.000000" -> "0".
inline std::string TrimmedNumber(std::string s) {
  if (s.find('.') == std::string::npos) return s;
  s.erase(s.find_last_not_of('0') + 1);
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

// Inputs: message  a CLI11 error message; positive  whether the option's check is CLI11's
//         PositiveNumber (its bound, the smallest double, prints as 0.000000 like NonNegativeNumber's).
// Returns it with "Value V not in range MIN to MAX" said readably: "Value V must be > 0" for a
// positive option, "Value V must be >= MIN" for another with no upper bound (MAX the largest
// double), else "Value V not in range MIN to MAX" with the bounds trimmed. Other messages are
// returned as they are.
inline std::string ReadableRangeMessage(const std::string& message, bool positive) {
  static const std::regex kRange(R"(Value (\S+) not in range (\S+) to (\S+))");
  std::smatch m;
  if (!std::regex_search(message, m, kRange)) return message;
  const std::string value = m[1], low = TrimmedNumber(m[2]), high = m[3];
  std::string said;
  if (positive) {
    said = "Value " + value + " must be > 0";
  } else if (std::strtod(high.c_str(), nullptr) >= 1e300) {
    said = "Value " + value + " must be >= " + low;
  } else {
    said = "Value " + value + " not in range " + low + " to " + TrimmedNumber(high);
  }
  return m.prefix().str() + said + m.suffix().str();
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_RANGE_MESSAGE_H_
