// printf-style formatting into a std::string of whatever length the values need (fixed buffers
// cut absurd values short: a speed of 1e300 prints 301 digits). Header-only.
#ifndef CLOTHWIND_COMMON_FORMATTED_H_
#define CLOTHWIND_COMMON_FORMATTED_H_

#include <cstdio>
#include <string>

namespace clothwind {

// Inputs: format  a printf format; args  its arguments (as printf takes them).
// Returns the formatted text, whole.
template <typename... Args>
std::string Formatted(const char* format, Args... args) {
  const int n = std::snprintf(nullptr, 0, format, args...);
  std::string text(n > 0 ? static_cast<size_t>(n) : 0, '\0');
  if (n > 0) std::snprintf(text.data(), text.size() + 1, format, args...);
  return text;
}

// A number as a message says it: "0.04" and "5", not std::to_string's "0.040000" and
// "5.000000"; twelve significant digits keep a bag time's decimals (1700000000.123).
inline std::string FormattedNumber(double v) { return Formatted("%.12g", v); }

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_FORMATTED_H_
