// Command-line numbers and the guard around a bench program's main, shared by the bench
// programs: a bad value is said naming its option, and any error ends the program with its
// message and status 1 (an uncaught exception ended it with SIGABRT and "terminate called after
// throwing ... what(): stod", naming no option).
#ifndef CLOTHWIND_BENCH_BENCH_ARGS_H_
#define CLOTHWIND_BENCH_BENCH_ARGS_H_

#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

namespace clothwind::bench {

// `text` as a finite number, the value of `option`.
// Throws std::invalid_argument naming the option and the text when it is not one.
inline double Number(const std::string& option, const std::string& text) {
  size_t used = 0;
  double v = 0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v))
    throw std::invalid_argument(option + ": expected a finite number, got '" + text + "'");
  return v;
}

// `text` as a whole number, the value of `option`. Throws as Number does.
inline int Integer(const std::string& option, const std::string& text) {
  const double v = Number(option, text);
  if (v != std::floor(v) || std::abs(v) > 2e9)
    throw std::invalid_argument(option + ": expected a whole number, got '" + text + "'");
  return static_cast<int>(v);
}

// Whether the arguments ask for help (-h or --help); if so, prints `usage` (a line) on stdout.
inline bool HelpAsked(int argc, char** argv, const char* usage) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::printf("%s\n", usage);
      return true;
    }
  }
  return false;
}

// The bench's one optional positional number (argv[1]), or `fallback` when there is none; at
// least `min`. Throws std::invalid_argument naming `what` for anything else, or for a second
// argument: atoi read "--help" as 0, and the bench ran.
inline int OptionalCount(int argc, char** argv, const std::string& what, int fallback, int min) {
  if (argc > 2) throw std::invalid_argument(std::string("one argument at most (") + what + "), got " + argv[2]);
  if (argc < 2) return fallback;
  const int n = Integer(what, argv[1]);
  if (n < min) throw std::invalid_argument(what + ": expected at least " + std::to_string(min) + ", got " + argv[1]);
  return n;
}

// Runs body(argc, argv) and returns its status; an exception is printed as
// "<name>: error: <what>" and gives status 1. A bench built otherwise than Release says so first
// on stderr (the sanitizer builds make them too, and their figures read like any others).
inline int Guarded(const char* name, int argc, char** argv, int (*body)(int, char**)) {
#ifdef CLOTHWIND_BENCH_BUILD_TYPE
  if (std::string(CLOTHWIND_BENCH_BUILD_TYPE) != "Release")
    std::fprintf(stderr, "%s: built as '%s', not Release: its figures are not the ones the docs report\n", name,
                 CLOTHWIND_BENCH_BUILD_TYPE);
#endif
  try {
    return body(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
    return 1;
  }
}

}  // namespace clothwind::bench

#endif  // CLOTHWIND_BENCH_BENCH_ARGS_H_
