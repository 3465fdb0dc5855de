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

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_FORMATTED_H_
