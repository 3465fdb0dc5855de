// clothwind train-fly-judge: trains the learned judge of which way a flag flies (learn/fly_judge.h)
// on a dataset's training clips, measures it on every split (each clip and, by the judge's
// antisymmetry, its mirror image) and writes it with a card of how it was made and how often it
// is right. A model trained without flips (train --no-flip) uses the judge beside it on
// ~flag_flies auto (docs/sdn.md, "Flags that fly left").
#include <ATen/Parallel.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "learn/dataset.h"
#include "learn/fly_judge_train.h"
#include "learn/model_config.h"
#include "fly_judge_table.h"
#include "progress_bar.h"
#include "dataset_outputs.h"
#include "output_paths.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct JudgeArgs {
  std::string data, out, measure;
  int windows = 3, frames = 30, threads = 2;
  double margin = 1.0;  // scores closer to 0 tell nothing (FlyJudge::margin)
  bool overwrite = false;
  learn::FlyJudgeTrainOptions train;
  // The test split is also judged slid by each of these many cells (ShiftedMotionMaps).
  static constexpr int kShiftedRows = 3;
  JudgeArgs() { train.shift = 3; }
};

learn::MotionMaps Collect(const learn::Dataset& dataset, const std::string& split, int frames, int windows) {
  const std::vector<learn::ClipInfo> clips = learn::SelectSplit(dataset, split);
  ProgressBar::Options b;
  b.label = "motion maps (" + split + ")";
  b.unit = "clips";
  ProgressBar bar(b);
  learn::MotionMaps maps = learn::CollectMotionMaps(clips, frames, windows, [&](int d, int t) { bar.Update(d, t); });
  bar.Finish();
  return maps;
}

VerbRegistrar registrar("train-fly-judge", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<JudgeArgs>();
  auto* sub = app.add_subcommand("train-fly-judge",
                                 "train the judge of which way a flag flies (for models trained with --no-flip) on a "
                                 "dataset of flags that fly right, and measure it on every split");
  sub->add_option("--data", a->data, "dataset folder (its flags must all fly right, as FlagSim's do)")->required();
  auto* out = sub->add_option("--out", a->out, "weights file, e.g. models/fly_judge.pt (its card .json is written beside it)");
  sub->add_flag("--overwrite", a->overwrite, "replace an existing --out and its card")->needs(out);
  auto* measure = sub->add_option("--measure", a->measure,
                                  "measure this judge (e.g. models/fly_judge.pt, its margin from its card) on every "
                                  "split instead of training one; writes nothing");
  out->excludes(measure);
  measure->excludes(out);
  sub->add_option("--windows", a->windows, "evenly spaced training windows per clip (val and test: the centred one)")
      ->check(CLI::Range(1, 1000))  // a huge count hung (windows rebuilt per window)
      ->capture_default_str();
  auto* frames = sub->add_option("--frames", a->frames, "frames per window (the models'; with --measure: the judge's card's unless given)")
                     ->check(CLI::Range(2, 10000))
                     ->capture_default_str();
  // Options of the training alone: with --measure (which trains nothing) they were accepted and
  // ignored, refused now naming both.
  const std::vector<CLI::Option*> training = {
      sub->add_option("--hidden", a->train.hidden, "hidden units (1..4096)")->check(CLI::Range(1, 4096))->capture_default_str(),
      sub->add_option("--epochs", a->train.epochs, "passes over the training maps")->check(CLI::PositiveNumber)->capture_default_str(),
      sub->add_option("--batch", a->train.batch, "maps per Adam step")->check(CLI::PositiveNumber)->capture_default_str(),
      sub->add_option("--lr", a->train.learning_rate, "Adam's learning rate")->check(CLI::PositiveNumber)->capture_default_str(),
      sub->add_option("--weight-decay", a->train.weight_decay, "Adam's L2 term")->check(CLI::NonNegativeNumber)->capture_default_str(),
      sub->add_option("--seed", a->train.seed, "initialisation and order (0..2^64-1)")
          ->check(CLI::NonNegativeNumber)
          ->capture_default_str(),
      sub->add_option("--shift", a->train.shift,
                      "slide each training map by a random offset of up to this many cells of 16 each way (a camera "
                      "that does not centre the flag, as FlagSim's all do; 0: as collected)")
          ->check(CLI::Range(0, learn::kMotionMapGrid / 2))
          ->capture_default_str()};
  for (CLI::Option* option : training) measure->excludes(option);
  sub->add_option("--threads", a->threads, "torch threads")->check(CLI::Range(1, 256))->capture_default_str();
  auto* margin = sub->add_option("--margin", a->margin,
                  "scores closer to 0 than this tell nothing (a calm or featureless clip: camera noise scores ~0.4, "
                  "a flying flag 5-12); 0..100 (with --measure: the judge's card's unless given)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  return [a, margin, frames]() {
    // CLI11's range lets NaN through: refused here, before the training, not after it.
    if (!std::isfinite(a->margin)) throw UsageError("--margin must be a number in 0..100, got nan");
    if (a->out.empty() && a->measure.empty()) throw UsageError("--out (to train a judge) or --measure (to measure one) is required");
    if (a->measure.empty()) {
      // The weights and their card beside them: on neither the dataset's index nor each other,
      // checked before the training, not after it.
      const std::filesystem::path card = learn::ConfigPathFor(a->out);
      const std::filesystem::path index = std::filesystem::path(a->data) / "index.json";
      if (SameFile(a->out, card))
        throw UsageError("--out " + a->out + ": the judge's card is written beside it with the "
                                    "extension .json, so --out needs another (e.g. .pt)");
      RefuseOutputOverInput("--out", a->out, {index});
      RefuseOutputOverInput("--out's card", card, {index});
      RefuseOutputInsideExamples("--out", a->out, a->data);
      RefuseOutputInsideExamples("--out's card", card, a->data);
      RefuseFolderAsOutput("--out", a->out);
      RefuseFolderAsOutput("--out's card", card);
      RefuseUnwritableFolder("--out", a->out);
      RefuseExistingOutput("--out", {a->out, card}, a->overwrite);
    }
    at::set_num_threads(a->threads);
    const learn::Dataset dataset = learn::ReadDataset(a->data);
    // The judge learns which way a flag flies from flags that all fly right (mirrored for left):
    // FlagSim's, or recorded ones (make run's rendered session records such). A toy dataset's
    // stripes or a hanging cloth show no flag: a judge trained on stripes scored 0 %, exit 0.
    if (dataset.kind == "toy" || dataset.kind == "cloth")
      throw UsageError("--data " + a->data + " is a \"" + dataset.kind +
                                  "\" dataset, with no flag; the fly judge is trained and measured on flags flying right "
                                  "(a FlagSim dataset, make-dataset --kind flag, or recorded flags)");
    // Measured: the judge first, so a wrong path fails before the frames are read.
    std::optional<learn::FlyJudge> measured;
    if (!a->measure.empty()) {
      measured = learn::FlyJudge::Load(a->measure);
      if (margin->count() > 0) measured->set_margin(a->margin);
      // Measured on windows as long as it was trained on.
      if (frames->count() == 0) {
        std::ifstream in(learn::ConfigPathFor(a->measure));
        const nlohmann::json card = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
        // Bounded as --frames is (the card's value was taken unchecked, past CLI11's range).
        if (card.is_object() && card.contains("frames")) {
          const nlohmann::json& f = card["frames"];
          if (!f.is_number_integer() || f.get<int64_t>() < 2 || f.get<int64_t>() > 10000)
            throw std::invalid_argument(learn::ConfigPathFor(a->measure).string() + ": field \"frames\" is " + f.dump() +
                                        ", expected a whole number in 2..10000 (or give --frames)");
          a->frames = f.get<int>();
        }
      }
    }
    const learn::MotionMaps train = Collect(dataset, "train", a->frames, a->windows);
    if (train.maps.empty() && !measured) {
      std::cerr << "train-fly-judge: " << (std::filesystem::path(a->data) / "index.json").string()
                << " lists no clips in split train\n";
      return 2;
    }
    const learn::MotionMaps val = Collect(dataset, "val", a->frames, 1);
    const learn::MotionMaps test = Collect(dataset, "test", a->frames, 1);

    learn::FlyJudge judge = measured ? *measured : [&] {
      ProgressBar::Options b;
      b.label = "train-fly-judge";
      b.unit = "epochs";
      ProgressBar bar(b);
      learn::FlyJudge trained = learn::TrainFlyJudge(train.maps, a->train, [&](int epoch, int epochs, double loss) {
        bar.Update(epoch, epochs, "loss " + Num(loss));
      });
      bar.Finish();
      trained.set_margin(a->margin);
      return trained;
    }();

    nlohmann::json accuracy;
    std::ostringstream table;
    // The header from the first row's bands (every row has the same), over its columns.
    auto add_row = [&](const std::string& split, const learn::FlyJudgeAccuracy& acc) {
      if (table.tellp() == 0) table << FlyJudgeHeader(acc.bands);
      table << FlyJudgeRow(split, acc);
    };
    for (const auto& [name, maps] : {std::pair{"train", &train}, std::pair{"val", &val}, std::pair{"test", &test}}) {
      if (maps->maps.empty()) continue;
      const learn::FlyJudgeAccuracy acc = learn::MeasureFlyJudge(judge, *maps);
      accuracy[name] = learn::ToJson(acc);
      add_row(name, acc);
    }
    // The test clips as a camera that does not centre the flag would show them: each map slid by
    // d cells of 16 in the 8 directions (card: accuracy.test_shifted_<d>).
    for (int d = 1; d <= JudgeArgs::kShiftedRows && !test.maps.empty(); ++d) {
      const learn::FlyJudgeAccuracy acc = learn::MeasureFlyJudge(judge, learn::ShiftedMotionMaps(test, d));
      accuracy["test_shifted_" + Num(d)] = learn::ToJson(acc);
      add_row("test±" + Num(d), acc);
    }
    std::cout << table.str()
              << "(accuracy [%] overall and by the clips' wind speed; each clip's mirror image is judged left "
                 "exactly as often: the score is antisymmetric; test±d: each test map slid by d cells of 16 in the 8 "
                 "directions)\n";
    if (measured) return 0;
    const nlohmann::json card = learn::FlyJudgeTrainingCard(
        std::filesystem::absolute(a->data).lexically_normal().string(), a->windows, a->frames, a->train, accuracy);
    const std::filesystem::path parent = std::filesystem::path(a->out).parent_path();
    if (!parent.empty()) std::filesystem::create_directories(parent);
    judge.Save(a->out, card);
    std::cout << "wrote " << a->out << " and its card " << learn::ConfigPathFor(a->out).string() << "\n";
    return 0;
  };
});

}  // namespace
}  // namespace clothwind::tools
