#ifndef CLOTHWIND_TOOLS_VERB_REGISTRY_H_
#define CLOTHWIND_TOOLS_VERB_REGISTRY_H_

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace clothwind::tools {

// A verb adds its subcommand to the app and returns the function to run when it is chosen.
// The function returns the process exit code.
using VerbSetup = std::function<std::function<int()>(CLI::App& app)>;

struct Verb {
  std::string name;
  VerbSetup setup;
};

// All verbs, in registration order. Verbs register from static initialisers in their own files
// (compiled straight into the executable, so the linker keeps them).
inline std::vector<Verb>& Verbs() {
  static std::vector<Verb> verbs;
  return verbs;
}

struct VerbRegistrar {
  VerbRegistrar(std::string name, VerbSetup setup) {
    Verbs().push_back({std::move(name), std::move(setup)});
  }
};

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_VERB_REGISTRY_H_
