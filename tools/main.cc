// clothwind <verb> ...: the offline tools behind one command line.
#include <algorithm>
#include <exception>
#include <iostream>
#include <map>

#include <CLI/CLI.hpp>

#include "learn/heap_reuse.h"
#include "verb_registry.h"

int main(int argc, char** argv) {
  // Training allocates and frees the same tensors every batch: keep the freed memory instead of
  // faulting its pages in again (a training step 7 % faster at 64 px, 13 % at 96, on 2 cores).
  clothwind::learn::KeepFreedHeapForReuse();
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
