// clothwind <verb> ...: the offline tools behind one command line.
#include <algorithm>
#include <exception>
#include <iostream>
#include <map>

#include <CLI/CLI.hpp>

#include "verb_registry.h"

int main(int argc, char** argv) {
  CLI::App app{"clothwind: wind and cloth measurement through simulation (offline tools)"};
  app.require_subcommand(1);
  auto& verbs = clothwind::tools::Verbs();
  std::sort(verbs.begin(), verbs.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<std::string, std::function<int()>> run;
  for (auto& verb : verbs) run[verb.name] = verb.setup(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  for (auto* sub : app.get_subcommands()) {
    try {
      return run.at(sub->get_name())();
    } catch (const std::exception& e) {
      std::cerr << "clothwind " << sub->get_name() << ": error: " << e.what() << "\n";
      return 1;
    }
  }
  return 2;
}
