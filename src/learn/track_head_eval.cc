#include "learn/track_head_eval.h"

#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <ATen/core/grad_mode.h>
#include <malloc.h>
#include <nlohmann/json.hpp>

#include "learn/aux_targets.h"
#include "learn/dataset.h"
#include "learn/networks.h"
#include "learn/track_targets.h"

namespace clothwind::learn {
namespace fs = std::filesystem;

namespace {

// The run's --aux-phases and --aux-world from state.json beside the model (a run's folder);
// 0 and false when there is none (a model copied out of its run).
void ReadRunAuxOptions(const fs::path& model, int* phase_bins, bool* world) {
  *phase_bins = 0;
  *world = false;
  const fs::path state = model.parent_path() / "state.json";
  if (!fs::exists(state)) return;
  const nlohmann::json j = ReadJson(state);
  // Checked by type, naming the file: value() threw bare type errors after a whole evaluation.
  if (j.contains("aux_phase_bins")) {
    if (!j["aux_phase_bins"].is_number_integer() || j["aux_phase_bins"].get<int64_t>() < 0)
      throw std::runtime_error(state.string() + ": field \"aux_phase_bins\" is " + j["aux_phase_bins"].dump() +
                               ", expected a whole number >= 0");
    *phase_bins = j["aux_phase_bins"].get<int>();
  }
  if (j.contains("aux_world")) {
    if (!j["aux_world"].is_boolean())
      throw std::runtime_error(state.string() + ": field \"aux_world\" is " + j["aux_world"].dump() +
                               ", expected true or false");
    *world = j["aux_world"].get<bool>();
  }
}

// Sums for an R² pooled over targets: each target's squared error and its spread around its own
// mean over the clips.
struct Pooled {
  double se = 0, ss = 0;
  long count = 0;
  void Add(const std::vector<std::vector<float>>& predicted, const std::vector<std::vector<float>>& truth, int k) {
    double mean = 0;
    for (const auto& row : truth) mean += row[k];
    mean /= static_cast<double>(truth.size());
    for (size_t i = 0; i < truth.size(); ++i) {
      se += std::pow(predicted[i][k] - truth[i][k], 2);
      ss += std::pow(truth[i][k] - mean, 2);
      ++count;
    }
  }
  double rmse() const { return count ? std::sqrt(se / count) : std::nan(""); }
  double r2() const { return ss > 0 ? 1 - se / ss : std::nan(""); }
};

}  // namespace

namespace {

// The head's checks on a loaded network (EvaluateTrackHead, CheckTrackHead): the window in frames.
int CheckedHeadWindow(const fs::path& model, const ModelConfig& config, int window) {
  if (config.aux_outputs <= 0)
    throw std::runtime_error(model.string() + ": the model has no track head (trained without --aux-tracks, or "
                             "exported: `clothwind export-model` drops it); give a run's own model.pt");
  const int frames = window == 0 ? config.frames : window;
  if (frames < config.frames || frames % config.frames != 0)
    throw std::invalid_argument("EvaluateTrackHead: window " + std::to_string(window) + " must be 0 or a multiple of " +
                                "the model's " + std::to_string(config.frames) + " frames");
  return frames;
}

}  // namespace

void CheckTrackHead(const fs::path& model, int window) {
  WindNet net = LoadWindNet(model);
  CheckedHeadWindow(model, net->config(), window);
  int phase_bins = 0;
  bool world = false;
  ReadRunAuxOptions(model, &phase_bins, &world);
}

TrackHeadReport EvaluateTrackHead(const fs::path& model, const fs::path& data, const std::string& split,
                                  int threads, int batch, const std::function<void(int, int)>& progress,
                                  int window) {
  const auto start = std::chrono::steady_clock::now();
  if (threads > 0) at::set_num_threads(threads);
  WindNet net = LoadWindNet(model);
  TrackHeadReport r;
  r.config = net->config();
  r.split = split;
  r.window = CheckedHeadWindow(model, r.config, window);
  int phase_bins = 0;
  bool world = false;
  ReadRunAuxOptions(model, &phase_bins, &world);
  const SampleOptions options = r.config.Sampling();
  const int parts = r.window / r.config.frames;  // consecutive model inputs per window
  const Dataset dataset = ReadDataset(data);
  // The scale training standardised the head's targets by: its train split's.
  const AuxTargets train = ReadAuxTargets(SelectSplit(dataset, "train"), options, phase_bins, world);
  if (train.outputs() != r.config.aux_outputs)
    throw std::runtime_error((model.parent_path() / "state.json").string() + ": the head has " +
                             std::to_string(r.config.aux_outputs) + " outputs, " + (data / "index.json").string() +
                             "'s tracks give " + std::to_string(train.outputs()) + " with --aux-phases " +
                             std::to_string(phase_bins) + (world ? " and --aux-world" : "") +
                             ": another dataset or run options than the model's");
  const std::vector<ClipInfo> clips = SelectSplit(dataset, split);
  if (clips.empty()) throw std::runtime_error((data / "index.json").string() + ": no examples in split " + split);
  // As Evaluate and Train: clips at another rate, or grey for a colour model, are another input.
  CheckClipsSuitModel(clips, r.config.frame_rate, r.config.colour, r.window);
  // The split's own tracks (the train split's are read already: not again, nor copied, ~1 GB on e5).
  AuxTargets read;
  if (split != "train") read = ReadAuxTargets(clips, options, phase_bins, world);
  const AuxTargets& tracks = split == "train" ? train : read;
  r.points = tracks.tracks[0].points();
  const int outputs = r.config.aux_outputs;
  batch = std::max(1, batch);
  at::NoGradGuard no_grad;
  for (size_t i = 0; i < clips.size(); i += batch) {
    const size_t end = std::min(clips.size(), i + static_cast<size_t>(batch));
    // Clip j's part q is sample (j - i) * parts + q: its window's q-th run of config.frames frames.
    std::vector<Sample> samples;
    std::vector<int> window_first;
    for (size_t j = i; j < end; ++j) {
      const int first = (clips[j].num_frames - r.window) / 2;  // the centred window, as Sampling()'s
      if (first < 0)
        throw std::runtime_error(clips[j].name + ": " + std::to_string(clips[j].num_frames) +
                                 " frames, fewer than the window's " + std::to_string(r.window));
      window_first.push_back(first);
      for (int q = 0; q < parts; ++q) {
        SampleOptions part = options;
        part.first_frame = first + q * r.config.frames;
        samples.push_back(LoadSample(clips[j], part, 0));
      }
    }
    const int64_t per = static_cast<int64_t>(samples[0].pixels.size());
    at::Tensor input = at::empty({static_cast<int64_t>(samples.size()), options.channels(), options.frames,
                                  options.input_size, options.input_size});
    for (size_t j = 0; j < samples.size(); ++j)
      std::copy(samples[j].pixels.begin(), samples[j].pixels.end(), input.data_ptr<float>() + j * per);
    const at::Tensor aux = net->ForwardWithAux(input).aux.to(at::kFloat).contiguous();
    for (size_t j = i; j < end; ++j) {
      const Sample& s = samples[(j - i) * parts];
      r.names.push_back(clips[j].name);
      r.wind.push_back(clips[j].wind_speed);
      r.truth.push_back(AuxTargetsOf(tracks.tracks[j], window_first[j - i], r.window, s.crop, clips[j].width,
                                     s.flipped, phase_bins, world));
      std::vector<float> y(outputs, 0.0f);
      for (int q = 0; q < parts; ++q) {
        const float* row = aux.data_ptr<float>() + ((j - i) * parts + q) * outputs;
        for (int k = 0; k < outputs; ++k) y[k] += (row[k] * train.scale.std[k] + train.scale.mean[k]) / parts;
      }
      r.predicted.push_back(std::move(y));
    }
    if (progress) progress(static_cast<int>(r.names.size()), static_cast<int>(clips.size()));
    ::malloc_trim(0);  // as Evaluate: hand each batch's pages back
  }
  // Figures. Positions are in [-1, 1] across the input: a pixel of it is 2 / input_size.
  const double px = options.input_size / 2.0;
  Pooled x, y, both;
  std::vector<Pooled> bins(kTrackBins);
  for (int p = 0; p < r.points; ++p) {
    x.Add(r.predicted, r.truth, p * kTargetsPerPoint);
    y.Add(r.predicted, r.truth, p * kTargetsPerPoint + 1);
    for (int c = 0; c < 2; ++c) both.Add(r.predicted, r.truth, p * kTargetsPerPoint + c);
    for (int j = 1; j <= kTrackBins; ++j)
      for (int c = 0; c < 2; ++c) bins[j - 1].Add(r.predicted, r.truth, p * kTargetsPerPoint + 2 + c * kTrackBins + j - 1);
  }
  r.position_rmse_x = x.rmse() * px;
  r.position_rmse_y = y.rmse() * px;
  r.position_r2 = both.r2();
  for (const Pooled& b : bins) {
    r.amplitude_rmse.push_back(b.rmse());
    r.amplitude_r2.push_back(b.r2());
  }
  double se = 0;
  for (size_t i = 0; i < r.truth.size(); ++i)
    for (int k = 0; k < outputs; ++k)
      se += std::pow((r.predicted[i][k] - r.truth[i][k]) / train.scale.std[k], 2);
  r.standardised_mse = se / (static_cast<double>(r.truth.size()) * outputs);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

std::string TrackHeadTable(const TrackHeadReport& r) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(3);
  s << "track head of " << r.config.Name() << " on " << r.names.size() << " " << r.split << " clips, " << r.points
    << " points, " << r.window << "-frame centred window";
  if (r.window != r.config.frames) s << " (" << r.window / r.config.frames << " inputs averaged)";
  s << "\n";
  s << "window-mean position  rmse x " << r.position_rmse_x << " px, y " << r.position_rmse_y << " px (of "
    << r.config.input_size << "), R^2 " << r.position_r2 << "\n";
  for (size_t j = 0; j < r.amplitude_rmse.size(); ++j)
    s << "log amplitude bin " << j + 1 << "  rmse " << r.amplitude_rmse[j] << ", R^2 " << r.amplitude_r2[j] << "\n";
  s << "standardised mse (AuxLoss) " << r.standardised_mse << "  [" << std::setprecision(1) << r.seconds << " s]\n";
  return s.str();
}

void WriteTrackHeadRows(const TrackHeadReport& r, const fs::path& file) {
  std::ostringstream s;
  const int outputs = r.config.aux_outputs;
  s << "# name\twind [m/s]\tpredicted[" << outputs << "]\ttruth[" << outputs << "]  (TrackTargets' order, "
    << r.points << " points, input " << r.config.input_size << " px, " << r.window << " frames)\n";
  s << std::setprecision(7);
  for (size_t i = 0; i < r.names.size(); ++i) {
    s << r.names[i] << '\t' << r.wind[i];
    for (float v : r.predicted[i]) s << '\t' << v;
    for (float v : r.truth[i]) s << '\t' << v;
    s << '\n';
  }
  WriteFileAtomically(file, s.str());
}

}  // namespace clothwind::learn
