// clothwind make-toy-dataset: a small synthetic dataset in the docs/dataset.md format whose
// stripes oscillate at a frequency set by the wind speed label (f = 1 + 0.5 v Hz), for smoke
// tests of training, evaluation and sdn_node without FlagSim data.
#include <iostream>
#include <memory>

#include "learn/dataset.h"
#include "output_paths.h"
#include "progress_bar.h"
#include "verb_registry.h"

namespace clothwind::tools {
namespace {

struct ToyArgs {
  learn::ToyDatasetOptions o;
  std::string out;
};

VerbRegistrar registrar("make-toy-dataset", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<ToyArgs>();
  auto* sub = app.add_subcommand("make-toy-dataset",
                                 "synthetic oscillating-stripes dataset for smoke tests (not a FlagSim substitute)");
  sub->add_option("--out", a->out, "dataset folder")->required();
  sub->add_option("--clips", a->o.clips, "examples")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--frames", a->o.frames, "frames per example")->check(CLI::Range(2, 1000))->capture_default_str();
  sub->add_option("--size", a->o.size, "frame side [px]")->check(CLI::Range(16, 2048))->capture_default_str();
  sub->add_option("--seed", a->o.seed, "seed (0..2^64-1)")->check(CLI::NonNegativeNumber)->capture_default_str();
  return [a]() {
    RefuseUnwritableOutputFolder("--out", a->out);
    ProgressBar::Options b;
    b.label = "make-toy-dataset";
    b.unit = "examples";
    ProgressBar bar(b);
    learn::WriteToyDataset(a->out, a->o, [&](int done, int total) { bar.Update(done, total); });
    bar.Finish();
    std::cout << "wrote " << a->o.clips << " examples to " << a->out << "\n";
    return 0;
  };
});

}  // namespace
}  // namespace clothwind::tools
