// clothwind export-model: rewrites a trained model (model.pt + model.json) for shipping: its
// parameters in float16 (half the file; every weight rounded once, batch-norm statistics kept in
// float32), and with --calibrate-std its predicted standard deviation scaled so that errors on
// the validation split are one std rms (ModelConfig::std_scale). An auxiliary head (train
// --aux-tracks) is dropped. LoadWindNet, eval and sdn_node read either precision and compute in
// float32.
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "learn/dataset.h"
#include "learn/evaluate.h"
#include "learn/networks.h"
#include "learn/weights_io.h"
#include "progress_bar.h"
#include "dataset_outputs.h"
#include "output_paths.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct ExportArgs {
  std::string model, out, precision = "float16", calibrate_data;
  int threads = 2;
  bool overwrite = false;
};

VerbRegistrar registrar("export-model", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<ExportArgs>();
  auto* sub = app.add_subcommand("export-model",
                                 "rewrite a trained model (model.pt + model.json) for shipping: float16 "
                                 "weights, optionally a std calibrated on the validation split");
  sub->add_option("--model", a->model, "trained model.pt (model.json beside it)")->required();
  sub->add_option("--out", a->out, "output .pt (its .json is written beside it)")->required();
  sub->add_flag("--overwrite", a->overwrite, "replace an existing --out and its .json");
  sub->add_option("--precision", a->precision, "precision of the parameters in the file")
      ->check(CLI::IsMember({"float16", "float32"}))
      ->capture_default_str();
  auto* calibrate = sub->add_option("--calibrate-std", a->calibrate_data,
                                    "dataset folder whose val split sets the std's scale (errors one std rms)");
  // Only the calibration runs the network: without it --threads was accepted and did nothing.
  sub->add_option("--threads", a->threads, "torch threads for the calibration (with --calibrate-std)")
      ->check(CLI::Range(1, 256))
      ->needs(calibrate)
      ->capture_default_str();
  return [a]() {
    if (std::filesystem::exists(a->out) && std::filesystem::equivalent(a->model, a->out)) {
      std::cerr << "export-model: --out must differ from --model (" << a->out << ")\n";
      return 2;
    }
    // The weights and their .json beside them: neither may land on an input, nor on each other.
    const std::filesystem::path out_config = learn::ConfigPathFor(a->out);
    const std::vector<std::filesystem::path> inputs = {
        a->model, learn::ConfigPathFor(a->model),
        a->calibrate_data.empty() ? std::filesystem::path() : std::filesystem::path(a->calibrate_data) / "index.json"};
    RefuseOutputOverInput("--out", a->out, inputs);
    RefuseOutputOverInput("--out's .json", out_config, inputs);
    RefuseOutputInsideExamples("--out", a->out, a->calibrate_data);
    RefuseOutputInsideExamples("--out's .json", out_config, a->calibrate_data);
    RefuseFolderAsOutput("--out", a->out);
    RefuseFolderAsOutput("--out's .json", out_config);
    if (SameFile(a->out, out_config))
      throw UsageError("--out " + a->out + ": the weights' configuration is written beside them with "
                                  "the extension .json, so --out needs another (e.g. .pt)");
    RefuseExistingOutput("--out", {a->out, out_config}, a->overwrite);
    // Before the minute of loading and calibrating: /proc/NAME.pt failed after it, naming a
    // temporary file.
    RefuseUnwritableFolder("--out", a->out);
    learn::WindNet net = learn::LoadWindNet(a->model);
    // A head trained beside the wind's (--aux-tracks) only shaped the trunk: no estimate reads it.
    if (net->config().aux_outputs > 0) {
      std::cout << "dropping the auxiliary head (" << net->config().aux_outputs << " outputs): no estimate reads it\n";
      net = learn::WithoutAuxHead(net);
    }
    std::cout << std::fixed << std::setprecision(3);
    if (!a->calibrate_data.empty()) {
      // Checked before the work, with the way out: Evaluate's "no examples in split val" left the
      // user to guess that the option needs one.
      if (learn::SelectSplit(learn::ReadDataset(a->calibrate_data), "val").empty())
        throw UsageError("--calibrate-std " + a->calibrate_data +
                                    ": the dataset has no val split, which calibration reads; give one that has, or "
                                    "leave --calibrate-std out (the std is then the network's own)");
    }
    // Made once the inputs have loaded (a missing --model or dataset left an empty folder behind),
    // still before the calibration's minute rather than at the write after it.
    // Taken away again, while empty, when the calibration fails (MadeFolders).
    const MadeFolders folders = MakeFoldersFor("--out", a->out);
    if (!a->calibrate_data.empty()) {
      ProgressBar::Options b;
      b.label = "calibrate";
      b.unit = "clips";
      ProgressBar bar(b);
      // Read as filmed (right), as FlagSim's flags fly: the scale is the model's own spread on clips
      // whose way is known. A fly judge's misreadings (auto) are not the model's error, and the
      // judge beside a training run's model.pt is not the one the node will use (models/ ships
      // fly_judge.pt beside the exported file): read with auto, the card's recipe calibrated on the
      // motion cues' 7-9 % misjudged clips, each ~8 stds off.
      const learn::EvalResult r =
          learn::Evaluate(a->model, a->calibrate_data, "val", a->threads, "cpu", 16, 1, false, false,
                          learn::FlagFlies::kRight, [&](int done, int total) { bar.Update(done, total); });
      bar.Finish();
      const double k = learn::CalibrationScale(r);
      // Within m stds scaled by k is within m·k of the raw stds.
      const double one = learn::StdCoverage(r, 1), two = learn::StdCoverage(r, 2);
      const double one_k = learn::StdCoverage(r, k), two_k = learn::StdCoverage(r, 2 * k);
      std::cout << "std calibration on " << r.truth.size() << " val clips: scale " << k << " (errors within 1 / 2 std: "
                << one << " / " << two << " before, " << one_k << " / " << two_k << " after)\n";
      net->set_std_scale(net->config().std_scale * k);
    }
    RemakeFolderFor(a->out);
    learn::SaveWindNet(net, a->out, learn::ParseWeightPrecision(a->precision));
    const double in_mb = std::filesystem::file_size(a->model) / 1e6;
    const double out_mb = std::filesystem::file_size(a->out) / 1e6;
    std::cout << std::setprecision(1) << "wrote " << a->out << " (" << net->config().Name() << ", " << a->precision
              << ", std scale " << std::setprecision(3) << net->config().std_scale << std::setprecision(1)
              << "): " << out_mb << " MB from " << in_mb << " MB\n";
    return 0;
  };
});

}  // namespace
}  // namespace clothwind::tools
