// The exit statuses of `clothwind`, and the error a verb throws for a command line it cannot run.
#ifndef CLOTHWIND_TOOLS_USAGE_ERROR_H_
#define CLOTHWIND_TOOLS_USAGE_ERROR_H_

#include <stdexcept>
#include <string>
#include <type_traits>

#include "common/formatted.h"

namespace clothwind::tools {

// Exit statuses, the same for every verb (README, `clothwind --help`):
constexpr int kExitFailed = 1;      // the work failed: an input missing or refused, a write that failed, a
                                    // bag not fit for replay (bag-check)
constexpr int kExitUsage = 2;       // the command line is wrong: an unknown verb or option, a value out of
                                    // range, options that exclude each other; nothing was done
// Ctrl-C or SIGTERM: the verb removes what it had half written and dies of the signal (a shell
// reports 130 or 143; tools/remove_on_interrupt.h).

// Thrown by a verb's own checks of its options (ranges, combinations), before any work: main exits
// kExitUsage for it, as for CLI11's parse errors, so a script tells a mistyped option from an input
// that failed (`bag-check BAG --gap-tolerance 0 || echo bad bag` said a bad option was a bad bag).
struct UsageError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// A number as a message says it: "5" and "0.05", not std::to_string's "5.000000" and
// "0.050000" ("--minutes ... got 0.000000"); whole numbers as they are.
inline std::string Num(double v) { return FormattedNumber(v); }
template <typename T, typename = std::enable_if_t<std::is_integral_v<T>>>
std::string Num(T v) {
  return std::to_string(v);
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_USAGE_ERROR_H_
