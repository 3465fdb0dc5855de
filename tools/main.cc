// clothwind <verb> ...: the offline tools behind one command line.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "closest_name.h"
#include "range_message.h"
#include "usage_error.h"
#include "verb_registry.h"

// package.xml's version, defined by tools/CMakeLists.txt; scripts/device-train compiles this file
// without CMake.
#ifndef CLOTHWIND_VERSION
#define CLOTHWIND_VERSION "(version unknown: built outside CMake)"
#endif

int main(int argc, char** argv) {
  CLI::App app{"clothwind: wind and cloth measurement through simulation (offline tools)", "clothwind"};
  app.footer("Exit status: 0 done; 1 the work failed (an input missing or refused, a write failed, bag-check: a\n"
             "bag not fit for replay); 2 the command line is wrong (nothing was done); Ctrl-C: the signal's (130).");
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("clothwind ") + CLOTHWIND_VERSION);
  auto& verbs = clothwind::tools::Verbs();
  std::sort(verbs.begin(), verbs.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<std::string, std::function<int()>> run;
  for (auto& verb : verbs) run[verb.name] = verb.setup(app);
  // No option takes a number that is not finite, and CLI11's Range, PositiveNumber and
  // NonNegativeNumber let "nan" through (every comparison with NaN is false): `train --still-floor
  // nan` ran as the default taken for given, `render --fps nan` reached the renderer. Refused for
  // every floating-point option (CLI11's type name FLOAT, its validators' descriptions after a
  // ':'), naming it; not for text, where `--out inf` or a folder named nan is a name.
  // A transform, not a check: CLI11 runs transforms before an option's own checks, which said
  // "Value abc must be > 0" of a word and "must be > 0" of `--lr inf`.
  const CLI::Validator finite(
      [](std::string& value) -> std::string {
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (end == value.c_str() || *end != '\0') return "expected a number, got " + value;
        if (!std::isfinite(v)) return "expected a finite number, got " + value;  // nan, inf, 1e400
        return "";
      },
      "", "finite");
  // An unsigned option (seeds, counts) takes digits within 0..2^64-1: "-1" wrapped to 2^64-1 and
  // 2^64 or more was clamped to it, both run without a word (`render --seed -1`, `--seed 1e30`).
  const CLI::Validator whole(
      [](std::string& value) -> std::string {
        const bool digits = !value.empty() && value.find_first_not_of("0123456789") == std::string::npos;
        errno = 0;
        const unsigned long long v = digits ? std::strtoull(value.c_str(), nullptr, 10) : 0;
        if (!digits || errno == ERANGE) return "expected a whole number 0..18446744073709551615, got " + value;
        // Decimal, as written: CLI11 reads "010" as C's octal 8.
        value = std::to_string(v);
        return "";
      },
      "", "whole");
  // A signed whole-number option (counts, epochs, jobs) likewise: CLI11 read "010" as 8 and "0x10"
  // as 16 without a word (`make-dataset --count 010` ran 8 simulations), as a script's zero-padded
  // `printf %03d` writes them.
  const CLI::Validator signed_whole(
      [](std::string& value) -> std::string {
        const size_t sign = !value.empty() && (value[0] == '-' || value[0] == '+') ? 1 : 0;
        const bool digits = value.size() > sign && value.find_first_not_of("0123456789", sign) == std::string::npos;
        errno = 0;
        const long long v = digits ? std::strtoll(value.c_str(), nullptr, 10) : 0;
        if (!digits || errno == ERANGE) return "expected a whole number, got " + value;
        value = std::to_string(v);
        return "";
      },
      "", "whole");
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* option : sub->get_options()) {
      if (option->get_type_size() == 0) continue;
      // transform, not check: a check may not change the value (010 must reach CLI11 as 10), and
      // transforms run first.
      const std::string type = option->get_type_name();
      if (type.rfind("FLOAT", 0) == 0) option->transform(finite);
      if (type.rfind("UINT", 0) == 0) option->transform(whole);
      if (type.rfind("INT", 0) == 0) option->transform(signed_whole);
    }
  // No verb: the verbs are listed (CLI11 said only "A subcommand is required").
  if (argc < 2) {
    std::cerr << app.help() << "\nclothwind: a verb is required (above)\n";
    return clothwind::tools::kExitUsage;
  }
  // A word where the verb goes that names none: CLI11 said only "A subcommand is required".
  if (argc >= 2 && argv[1][0] != '-' && run.count(argv[1]) == 0) {
    std::cerr << "clothwind: unknown verb '" << argv[1] << "'";
    std::vector<std::string> names;
    for (const auto& verb : verbs) names.push_back(verb.name);
    const std::string closest = clothwind::tools::ClosestName(argv[1], names);
    if (!closest.empty()) std::cerr << "; did you mean " << closest << "?";
    std::cerr << " (clothwind --help lists the verbs)\n";
    return clothwind::tools::kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ValidationError& e) {
    // Which option: a positive one's lower bound prints like a non-negative one's (0.000000).
    const std::string what = e.what();
    bool positive = false;
    for (CLI::App* sub : app.get_subcommands())
      for (const CLI::Option* option : sub->get_options())
        if (what.rfind(option->get_name() + ":", 0) == 0)
          positive = option->get_type_name().find(":POSITIVE") != std::string::npos;
    std::cerr << clothwind::tools::ReadableRangeMessage(what, positive) << "\nRun with --help for more information.\n";
    return clothwind::tools::kExitUsage;
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every other parse error is a wrong command line, status 2 (CLI11's
    // own codes, 104 to 114, told a script nothing it could use).
    const int status = app.exit(e);
    return status == 0 ? 0 : clothwind::tools::kExitUsage;
  }
  // An empty value (`--out ""`, a shell variable that was not set) is no value: `eval --json ""`
  // ran as if no --json was given, and `train --out ""` failed after its checks with "cannot
  // create directories: Invalid argument []", naming no option. No option means anything by "".
  for (CLI::App* sub : app.get_subcommands())
    for (const CLI::Option* option : sub->get_options()) {
      if (option->count() == 0 || option->get_type_size_max() == 0) continue;  // not given, or a flag
      for (const std::string& value : option->results())
        if (value.empty()) {
          std::cerr << "clothwind " << sub->get_name() << ": error: " << option->get_name()
                    << ": an empty value; expected " << (option->get_type_name().empty() ? "one" : option->get_type_name())
                    << "\nRun with --help for more information.\n";
          return clothwind::tools::kExitUsage;
        }
    }
  for (auto* sub : app.get_subcommands()) {
    try {
      return run.at(sub->get_name())();
    } catch (const clothwind::tools::UsageError& e) {
      std::cerr << "clothwind " << sub->get_name() << ": error: " << e.what() << "\nRun with --help for more information.\n";
      return clothwind::tools::kExitUsage;
    } catch (const std::exception& e) {
      std::cerr << "clothwind " << sub->get_name() << ": error: " << e.what() << "\n";
      return clothwind::tools::kExitFailed;
    }
  }
  return 2;
}
