#include "learn/networks.h"

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

#include <stdexcept>

#include <ATen/ATen.h>

#include "common/atomic_file.h"
#include "common/json_file.h"
#include "learn/track_targets.h"
#include "learn/weight_average.h"

namespace clothwind::learn {
namespace {

torch::nn::Conv2d Conv(int in, int out, int kernel, int stride) {
  return torch::nn::Conv2d(
      torch::nn::Conv2dOptions(in, out, kernel).stride(stride).padding(kernel / 2).bias(false));
}

}  // namespace

BasicBlockImpl::BasicBlockImpl(int in_channels, int out_channels, int stride) {
  conv1_ = register_module("conv1", Conv(in_channels, out_channels, 3, stride));
  bn1_ = register_module("bn1", torch::nn::BatchNorm2d(out_channels));
  conv2_ = register_module("conv2", Conv(out_channels, out_channels, 3, 1));
  bn2_ = register_module("bn2", torch::nn::BatchNorm2d(out_channels));
  if (stride != 1 || in_channels != out_channels) {
    shortcut_ = register_module("shortcut", torch::nn::Sequential(Conv(in_channels, out_channels, 1, stride),
                                                                  torch::nn::BatchNorm2d(out_channels)));
  }
}

at::Tensor BasicBlockImpl::forward(const at::Tensor& x) {
  at::Tensor y = at::relu(bn1_->forward(conv1_->forward(x)));
  y = bn2_->forward(conv2_->forward(y));
  return at::relu(y + (shortcut_ ? shortcut_->forward(x) : x));
}

ResNet18TrunkImpl::ResNet18TrunkImpl(int in_channels, int width, bool stem_pool) : stem_pool_(stem_pool) {
  stem_ = register_module("stem", Conv(in_channels, width, 7, 2));
  stem_bn_ = register_module("stem_bn", torch::nn::BatchNorm2d(width));
  torch::nn::Sequential stages;
  int channels = width;
  for (int stage = 0; stage < 4; ++stage) {
    const int out = width << stage;
    stages->push_back(BasicBlock(channels, out, stage == 0 ? 1 : 2));
    stages->push_back(BasicBlock(out, out, 1));
    channels = out;
  }
  stages_ = register_module("stages", stages);
  features_ = channels;
  // He initialisation for convolutions (as torchvision's ResNet); batch norm starts at (1, 0).
  for (auto& module : modules(/*include_self=*/false)) {
    if (auto* conv = module->as<torch::nn::Conv2d>()) {
      torch::nn::init::kaiming_normal_(conv->weight, 0.0, torch::kFanOut, torch::kReLU);
    }
  }
}

at::Tensor ResNet18TrunkImpl::FeatureMap(const at::Tensor& x) { return StageMaps(x).back(); }

std::vector<at::Tensor> ResNet18TrunkImpl::StageMaps(const at::Tensor& x) {
  at::Tensor y = at::relu(stem_bn_->forward(stem_->forward(x)));
  if (stem_pool_) y = at::max_pool2d(y, {3, 3}, {2, 2}, {1, 1});
  std::vector<at::Tensor> maps;
  for (size_t block = 0; block < stages_->size(); ++block) {
    y = stages_->ptr<BasicBlockImpl>(block)->forward(y);
    if (block % 2 == 1) maps.push_back(y);  // two blocks a stage
  }
  return maps;
}

std::vector<int> ResNet18TrunkImpl::stage_channels() const {
  const int w = features_ / 8;  // the last stage's 8w
  return {w, 2 * w, 4 * w, 8 * w};
}

at::Tensor ResNet18TrunkImpl::Pooled(const at::Tensor& map) { return at::adaptive_avg_pool2d(map, {1, 1}).flatten(1); }

at::Tensor ResNet18TrunkImpl::forward(const at::Tensor& x) { return Pooled(FeatureMap(x)); }

WindNetImpl::WindNetImpl(const ModelConfig& config) : config_(config) {
  if (!IsKnownArch(config.arch)) {
    throw std::invalid_argument("WindNet: unknown architecture \"" + config.arch + "\"");
  }
  if (config.arch == "sdn") {
    const int candidates = config.SpectralCandidates();
    if (config.frames < 2 || config.k < 1 || config.k > candidates ||
        config.DftLength() < config.frames) {
      throw std::invalid_argument("WindNet: an SDN on " + std::to_string(config.frames) + " frames (DFT length " +
                                  std::to_string(config.DftLength()) +
                                  ") offers " + std::to_string(candidates) + " frequency bins, k = " +
                                  std::to_string(config.k));
    }
  }
  if (!config.PhaseStepFarIsValid() || (config.phase_step_far != 0 && config.arch != "sdn")) {
    throw std::invalid_argument("WindNet: phase_step_far " + std::to_string(config.phase_step_far) +
                                " must be 0, or a distance of at least 2 pixels on an SDN with phase steps");
  }
  if (const std::string field = config.SpectralOptionOffSdn(); !field.empty()) {
    throw std::invalid_argument("WindNet: " + field + " is an option of the spectral layer, which " + config.Name() +
                                " does not have");
  }
  if (!config.ModeShapeIsValid()) {
    throw std::invalid_argument("WindNet: mode_shape is an option of an SDN without include_dc, not of " + config.Name());
  }
  if (!config.SpectralPoolIsValid()) {
    throw std::invalid_argument("WindNet: spectral_pool " + std::to_string(config.spectral_pool) +
                                " must be >= 1, divide the input size " + std::to_string(config.input_size) +
                                " and be 1 unless the model is an SDN");
  }
  if (!config.FlowSizeIsValid()) {
    throw std::invalid_argument("WindNet: flow_size " + std::to_string(config.flow_size) +
                                " must be 0, or at least 16 on a model with flow");
  }
  if (!config.FrameChannelsAreValid()) {
    throw std::invalid_argument("WindNet: frame_channels " + std::to_string(config.frame_channels) +
                                " must be 0, or 1 to the clip's " + std::to_string(config.frames) +
                                " frames on an SDN, not on " + config.Name());
  }
  if (!config.ColourIsValid()) {
    throw std::invalid_argument("WindNet: flow and colour are exclusive (the flow is the grey frames'), in " + config.Name());
  }
  trunk_ = register_module("trunk", ResNet18Trunk(config.TrunkInputChannels(), config.width, config.stem_pool));
  if (config.arch == "lstm") {
    // Yang et al. read the last hidden state of an LSTM fed one CNN feature vector per frame.
    const int features = trunk_->feature_size();
    lstm_ = register_module("lstm", torch::nn::LSTM(torch::nn::LSTMOptions(features, features).batch_first(true)));
  }
  if (config.head_hidden < 0) throw std::invalid_argument("WindNet: head_hidden must be >= 0");
  // The output layer keeps the name "head" either way, so files of linear-head models load as before.
  int head_inputs = trunk_->feature_size();
  if (config.head_hidden > 0) {
    head_hidden_ = register_module("head_hidden", torch::nn::Linear(head_inputs, config.head_hidden));
    head_inputs = config.head_hidden;
  }
  head_ = register_module("head", torch::nn::Linear(head_inputs, 2));
  if (config.aux_outputs < 0) throw std::invalid_argument("WindNet: aux_outputs must be >= 0");
  if (config.aux_outputs > 0)
    aux_head_ = register_module("aux_head", torch::nn::Linear(trunk_->feature_size(), config.aux_outputs));
  if (!config.PointMapsAreValid()) {
    throw std::invalid_argument("WindNet: point_maps " + std::to_string(config.point_maps) +
                                " must be 0, or P points of an auxiliary head of at least 12 P outputs on " +
                                "an sdn or resnet18, not " + config.Name() + " with " +
                                std::to_string(config.aux_outputs));
  }
  if (config.point_maps > 0) {
    const int points = config.point_maps;
    point_head_ = register_module("point_head", PointMapHead(trunk_->stage_channels(), points));
    point_mean_ = register_buffer("point_mean", at::zeros({points, 2}));
    point_std_ = register_buffer("point_std", at::ones({points, 2}));
  }
}

void WindNetImpl::SetPointScale(const at::Tensor& mean, const at::Tensor& std) {
  if (!point_head_) throw std::invalid_argument("WindNet::SetPointScale: " + config_.Name() + " has no point maps");
  const std::vector<int64_t> shape = {config_.point_maps, 2};
  if (mean.sizes() != at::IntArrayRef(shape) || std.sizes() != at::IntArrayRef(shape) ||
      !(std.min().item<double>() > 0)) {
    throw std::invalid_argument("WindNet::SetPointScale: expected mean and std [" + std::to_string(config_.point_maps) +
                                ", 2] with std > 0");
  }
  at::NoGradGuard no_grad;
  point_mean_.copy_(mean);
  point_std_.copy_(std);
}

at::Tensor WindNetImpl::TrunkInput(const at::Tensor& clips) const {
  if (clips.dim() != 5 || clips.size(1) != config_.channels || clips.size(2) != config_.frames) {
    throw std::invalid_argument("WindNet " + config_.Name() + ": expected clips [N_b, " +
                                std::to_string(config_.channels) + ", " + std::to_string(config_.frames) +
                                ", H, W], got " + std::to_string(clips.dim()) + " dimensions " +
                                (clips.dim() >= 3 ? "with C=" + std::to_string(clips.size(1)) +
                                                        " N_t=" + std::to_string(clips.size(2))
                                                  : std::string()));
  }
  return WithCoordMaps(ArchImages(clips));
}

at::Tensor WindNetImpl::ArchImages(const at::Tensor& clips) const {
  if (config_.arch == "sdn") {
    SpectralMaps maps = SpectralDecomposition(clips, config_.Spectral());
    std::vector<at::Tensor> parts = {at::log1p(maps.power), maps.frequency * (2.0 / config_.frame_rate)};
    // The spectral maps see only motion; the mean image gives the trunk the flag's pose (its
    // droop), which at low wind says more about the speed than its small oscillations.
    if (config_.mean_map) parts.push_back(clips.mean(2));
    if (config_.phase_steps) parts.push_back(maps.phase);
    if (config_.mode_shape) parts.push_back(maps.mode);
    // A few of the (normalised) frames themselves: where the cloth is at those instants, which
    // no per-pixel spectrum keeps. [N_b, C, N, H, W] -> [N_b, C·N, H, W], channel c·N + i.
    if (config_.frame_channels > 0) {
      const at::Tensor indices = at::tensor(config_.FrameChannelIndices(), at::kLong).to(clips.device());
      parts.push_back(clips.index_select(2, indices).flatten(1, 2));
    }
    at::Tensor maps_in = at::cat(parts, 1);
    // Pooling after the per-pixel spectra, not before: a stripe's edge that moves by less than a
    // pooled pixel still shows its power here, where downsampling the frames first blurs it away.
    if (config_.spectral_pool > 1) {
      maps_in = at::avg_pool2d(maps_in, {config_.spectral_pool, config_.spectral_pool});
    }
    return maps_in;
  }
  if (config_.arch == "lstm") {
    return clips.transpose(1, 2).reshape({-1, clips.size(1), clips.size(3), clips.size(4)});
  }
  return clips.reshape({clips.size(0), clips.size(1) * clips.size(2), clips.size(3), clips.size(4)});
}

at::Tensor WindNetImpl::WithCoordMaps(const at::Tensor& images) const {
  if (!config_.coord_maps) return images;
  const int64_t n = images.size(0), h = images.size(2), w = images.size(3);
  const at::Tensor column = PixelCentres(w, images.options()), row = PixelCentres(h, images.options());
  const at::Tensor x = column.view({1, 1, 1, w}).expand({n, 1, h, w});
  const at::Tensor y = row.view({1, 1, h, 1}).expand({n, 1, h, w});
  return at::cat({images, x, y}, 1);
}

at::Tensor WindNetImpl::forward(const at::Tensor& clips) { return ForwardWithAux(clips).wind; }

WindNetImpl::Outputs WindNetImpl::ForwardWithAux(const at::Tensor& clips) {
  return ForwardImages(TrunkInput(clips), clips.size(0));
}

WindNetImpl::Outputs WindNetImpl::ForwardImages(const at::Tensor& images, int64_t batch) {
  const std::vector<at::Tensor> stage_maps = trunk_->StageMaps(images);
  at::Tensor features = ResNet18TrunkImpl::Pooled(stage_maps.back());
  if (config_.arch == "lstm") {
    // [N_b·N_t, F] -> [N_b, N_t, F] -> the LSTM's output after the last frame [N_b, F].
    at::Tensor sequence = std::get<0>(lstm_->forward(features.reshape({batch, -1, features.size(1)})));
    features = sequence.select(1, sequence.size(1) - 1);
  }
  // Dropout on the pooled features, in training only: the SDN fits its training clips better
  // than new ones (docs/sdn-experiments.md), and the head is where one feature can memorise a simulation.
  Outputs outputs;
  // The auxiliary head reads the features before dropout: it describes the clip, it does not
  // memorise a simulation.
  if (aux_head_) outputs.aux = aux_head_->forward(features);
  if (point_head_) {
    // [N_b, P, 2] in the image's unit square -> standardised as the targets, in place of the first two
    // of each point's kTargetsPerPoint columns (TrackTargets' point-major blocks come first).
    const at::Tensor positions = (point_head_->forward(stage_maps) - point_mean_) / point_std_;
    const int64_t n = outputs.aux.size(0), block = int64_t{config_.point_maps} * kTargetsPerPoint;
    const at::Tensor points = outputs.aux.narrow(1, 0, block).view({n, config_.point_maps, kTargetsPerPoint});
    outputs.aux = at::cat({at::cat({positions, points.narrow(2, 2, kTargetsPerPoint - 2)}, 2).flatten(1),
                           outputs.aux.narrow(1, block, outputs.aux.size(1) - block)},
                          1);
  }
  if (config_.dropout > 0) features = at::dropout(features, config_.dropout, is_training());
  if (head_hidden_) features = at::relu(head_hidden_->forward(features));
  at::Tensor out = head_->forward(features);
  outputs.wind = at::stack({out.select(1, 0), out.select(1, 1).clamp(-12.0, 8.0)}, 1);
  return outputs;
}

at::Tensor WindLoss(const at::Tensor& output, const at::Tensor& target) {
  at::Tensor mean = output.select(1, 0), log_var = output.select(1, 1);
  at::Tensor residual2 = (mean - target).square();
  at::Tensor nll = 0.5 * (log_var + residual2.detach() * at::exp(-log_var));
  return (residual2 + nll).mean();
}

at::Tensor AuxLoss(const at::Tensor& aux, const at::Tensor& target) { return (aux - target).square().mean(); }

void SaveWindNet(WindNet& net, const std::filesystem::path& weights, WeightPrecision precision) {
  // The configuration goes into the weights file as well as beside it: most of it (input size,
  // frames, frame rate, label scale, ...) shapes no tensor, so weights loaded under another
  // model.json would load without complaint and answer wrongly.
  // Written as a pair: a failure between the two left new weights beside the old model.json,
  // a pair the loader refuses, where a good model had been.
  const nlohmann::json config = ToJson(net->config());
  clothwind::WriteFilePairAtomically(weights.string(), SerializeModuleWeights(*net, precision, config.dump()),
                          ConfigPathFor(weights).string(), config.dump(2) + "\n");
}

WindNet WithoutAuxHead(WindNet& net) {
  ModelConfig config = net->config();
  config.aux_outputs = 0;
  config.point_maps = 0;
  WindNet stripped(config);
  CopyWeights(*net, *stripped);  // every tensor of the stripped network, by name, onto its CPU
  stripped->eval();
  return stripped;
}

namespace {

// Throws std::runtime_error naming config_path and every field in which `config` (read from it)
// differs from `stored`, the configuration SaveWindNet saved inside `weights`.
void CheckConfigMatchesWeights(const ModelConfig& config, const std::filesystem::path& config_path,
                               const std::string& stored, const std::filesystem::path& weights) {
  ModelConfig saved;
  try {
    saved = ModelConfigFromJson(nlohmann::json::parse(stored), weights.string() + " (its saved configuration)");
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(weights.string() + ": its saved configuration is not valid JSON: " + JsonErrorText(e));
  }
  // Compared through the struct, so keys a model.json may leave out (older files) compare as
  // their defaults.
  const nlohmann::json want = ToJson(saved), have = ToJson(config);
  std::string differences;
  for (const auto& [key, value] : want.items()) {
    if (have.contains(key) && have[key] == value) continue;
    differences += std::string(differences.empty() ? "" : "; ") + "field \"" + key + "\" is " +
                   (have.contains(key) ? have[key].dump() : std::string("missing")) + ", the weights' is " +
                   value.dump();
  }
  if (!differences.empty()) {
    throw std::runtime_error(config_path.string() + " does not describe the network whose weights are in " +
                             weights.string() + ": " + differences +
                             " (a model.json is written with its weights: restore the one written with them)");
  }
}

// WindNet(config), its std::invalid_argument rethrown as std::runtime_error naming config_path:
// ModelConfigFromJson makes the constructor's checks itself, so this only catches one added to
// the constructor and not there, which would otherwise stop eval or sdn_node naming no file.
WindNet BuildWindNet(const ModelConfig& config, const std::filesystem::path& config_path) {
  try {
    return WindNet(config);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(config_path.string() + ": " + e.what());
  }
}

}  // namespace

WindNet LoadWindNet(const std::filesystem::path& weights) {
  RequireWeightsFile(weights, "a model");
  const std::filesystem::path config_path = ConfigPathFor(weights);
  const nlohmann::json j = ReadJsonFile(config_path.string(), "the architecture of the model " + weights.string());
  WindNet net = BuildWindNet(ModelConfigFromJson(j, config_path.string()), config_path);
  std::string stored;
  try {
    LoadModuleWeights(*net, weights, &stored);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + " (" + config_path.string() + " describes a " +
                             net->config().Name() + " network)");
  }
  if (!stored.empty()) CheckConfigMatchesWeights(net->config(), config_path, stored, weights);
  net->eval();
  return net;
}

void UseChannelsLast(torch::nn::Module& module) {
  at::NoGradGuard no_grad;
  auto convert = [](at::Tensor& t) {
    if (t.defined() && t.dim() == 4) t.set_data(t.data().contiguous(at::MemoryFormat::ChannelsLast));
  };
  for (at::Tensor& p : module.parameters()) convert(p);
  for (at::Tensor& b : module.buffers()) convert(b);
}

}  // namespace clothwind::learn
