// clothwind export-model: rewrites a trained model (model.pt + model.json) for shipping, with its
// parameters in float16 (half the file; every weight rounded once, batch-norm statistics kept in
// float32). LoadWindNet, eval and sdn_node read either precision and compute in float32.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>

#include "learn/networks.h"
#include "learn/weights_io.h"
#include "verb_registry.h"

namespace clothwind::tools {
namespace {

struct ExportArgs {
  std::string model, out, precision = "float16";
};

VerbRegistrar registrar("export-model", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<ExportArgs>();
  auto* sub = app.add_subcommand("export-model",
                                 "rewrite a trained model (model.pt + model.json) in float16 for shipping");
  sub->add_option("--model", a->model, "trained model.pt (model.json beside it)")->required();
  sub->add_option("--out", a->out, "output .pt (its .json is written beside it)")->required();
  sub->add_option("--precision", a->precision, "precision of the parameters in the file")
      ->check(CLI::IsMember({"float16", "float32"}))
      ->capture_default_str();
  return [a]() {
    if (std::filesystem::exists(a->out) && std::filesystem::equivalent(a->model, a->out)) {
      std::cerr << "export-model: --out must differ from --model (" << a->out << ")\n";
      return 2;
    }
    learn::WindNet net = learn::LoadWindNet(a->model);
    learn::SaveWindNet(net, a->out, learn::ParseWeightPrecision(a->precision));
    const double in_mb = std::filesystem::file_size(a->model) / 1e6;
    const double out_mb = std::filesystem::file_size(a->out) / 1e6;
    std::cout << std::fixed << std::setprecision(1) << "wrote " << a->out << " (" << net->config().Name()
              << ", " << a->precision << "): " << out_mb << " MB from " << in_mb << " MB\n";
    return 0;
  };
});

}  // namespace
}  // namespace clothwind::tools
