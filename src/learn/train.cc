#include "learn/train.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <future>
#include <iomanip>
#include <iterator>
#include <limits>
#include <memory>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <ATen/core/grad_mode.h>
#include <nlohmann/json.hpp>
#include <torch/cuda.h>
#include <torch/types.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/adam.h>
#include <torch/serialize.h>

#include "common/atomic_file.h"
#include "common/formatted.h"
#include "common/json_file.h"
#include "common/regular_file.h"
#include "learn/aux_targets.h"
#include "learn/dataset.h"
#include "learn/frame_cache.h"
#include "learn/full_float32.h"
#include "learn/networks.h"
#include "learn/predictor.h"
#include "learn/track_targets.h"
#include "learn/weight_average.h"

namespace clothwind::learn {
namespace fs = std::filesystem;
namespace {

struct Batch {
  at::Tensor clips;   // [B, C, N_t, S, S] (C = SampleOptions::channels(): 1 grey, 3 with flow or colour)
  at::Tensor speeds;  // [B] [m/s]
  at::Tensor aux;     // [B, A] standardised track targets (undefined without them)
};

// Clips read at once while a batch loads. Loading is bound by file reads, not decoding, once the
// dataset outgrows the page cache (flagsim-e5's 9.6 GB on the 24 GiB VM, whose cache the host
// trims): one reader keeps one read in flight and left 37 % of the CPU idle there, four 20 %
// (eight no less).
// Each clip's sample depends only on its own seed, so a batch is the same for any number of readers.
constexpr int kBatchReaders = 4;

// Loads clips indices[begin, end) of `clips` as one batch, clip i augmented with seed
// seed_base + indices[i], its frames from `cache` when given (a cache of these same clips).
// Outputs: clips [end - begin, C, N_t, S, S] float (C = options.channels()), speeds [end - begin] m/s.
// With `aux`, the batch also holds each sample's standardised track targets, for its window, crop and flip.
Batch LoadBatch(const std::vector<ClipInfo>& clips, const std::vector<size_t>& indices, size_t begin, size_t end,
                const SampleOptions& options, uint64_t seed_base, FrameCache* cache, const AuxTargets* aux) {
  const int64_t n = static_cast<int64_t>(end - begin), s = options.input_size;
  Batch b{at::empty({n, options.channels(), options.frames, s, s}), at::empty({n}, at::kFloat), at::Tensor()};
  if (aux) b.aux = at::empty({n, aux->outputs()}, at::kFloat);
  float* pixels = b.clips.data_ptr<float>();
  float* speeds = b.speeds.data_ptr<float>();
  const int64_t clip_floats = n > 0 ? b.clips.numel() / n : 0;
  auto load = [&](int64_t first, int64_t last) {
    for (int64_t i = first; i < last; ++i) {
      const size_t clip = indices[begin + static_cast<size_t>(i)];
      Sample sample = cache ? LoadSample(*cache, clip, options, seed_base + clip)
                            : LoadSample(clips[clip], options, seed_base + clip);
      if (static_cast<int64_t>(sample.pixels.size()) != clip_floats)
        throw std::logic_error("LoadBatch: sample of " + std::to_string(sample.pixels.size()) +
                               " values, expected " + std::to_string(clip_floats));
      std::copy(sample.pixels.begin(), sample.pixels.end(), pixels + i * clip_floats);
      speeds[i] = static_cast<float>(sample.wind_speed);
      if (aux) {
        // A cache's crops are of its input_size squares; the files' of the clip's own frames.
        const int source_side = cache ? options.input_size : clips[clip].width;
        const std::vector<float> y =
            AuxTargetsOf(aux->tracks[clip], sample.first_frame, options.frames, sample.crop, source_side,
                         sample.flipped, aux->phase_bins, aux->world);
        float* row = b.aux.data_ptr<float>() + i * aux->outputs();
        for (int k = 0; k < aux->outputs(); ++k) row[k] = (y[k] - aux->scale.mean[k]) / aux->scale.std[k];
      }
    }
  };
  const int64_t readers = std::min<int64_t>(kBatchReaders, n);
  std::vector<std::future<void>> parts;
  for (int64_t r = 1; r < readers; ++r)
    parts.push_back(std::async(std::launch::async, load, n * r / readers, n * (r + 1) / readers));
  load(0, readers > 0 ? n / readers : 0);
  for (auto& part : parts) part.get();  // rethrows a reader's error
  return b;
}

nlohmann::json EpochJson(const EpochRecord& e) {
  return {{"epoch", e.epoch},         {"lr", e.lr},           {"train_loss", e.train_loss},
          {"val_loss", e.val_loss},   {"train_rmse", e.train_rmse}, {"val_rmse", e.val_rmse},
          {"val_acc05", e.val_acc05}, {"seconds", e.seconds}, {"train_aux_loss", e.train_aux_loss},
          {"raw_val_rmse", e.raw_val_rmse}, {"device", e.device}, {"threads", e.threads}};
}

// One epoch of state.json's log read back; `where` names it ("RUN/state.json: log[3]") in every
// refusal, which used to be nlohmann's bare "type must be number, but is null".
EpochRecord EpochFromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) throw std::runtime_error(where + ": expected an object (one epoch's record), got " + j.dump());
  auto field = [&](const char* name) -> const nlohmann::json* { return j.contains(name) ? &j[name] : nullptr; };
  auto refuse = [&](const char* name, const char* expected) {
    const nlohmann::json* v = field(name);
    throw std::runtime_error(where + "." + name + ": expected " + expected + ", got " + (v ? v->dump() : "nothing"));
  };
  // nlohmann writes a NaN or infinite double as null (JSON has no such numbers): an epoch whose
  // validation diverged is read back as NaN, or its run could never be resumed. `absent`: the
  // value of a field older runs did not write (NaN: the field is required).
  auto number = [&](const char* name, double absent) {
    const nlohmann::json* v = field(name);
    if (!v) {
      if (std::isnan(absent)) refuse(name, "a number (null for NaN)");
      return absent;
    }
    if (v->is_null()) return std::numeric_limits<double>::quiet_NaN();
    if (!v->is_number()) refuse(name, "a number (null for NaN)");
    return v->get<double>();
  };
  constexpr double kRequired = std::numeric_limits<double>::quiet_NaN();
  EpochRecord e;
  if (!field("epoch") || !j["epoch"].is_number_integer()) refuse("epoch", "an integer");
  e.epoch = j["epoch"].get<int>();
  e.lr = number("lr", kRequired);
  e.train_loss = number("train_loss", kRequired);
  e.val_loss = number("val_loss", kRequired);
  e.train_rmse = number("train_rmse", kRequired);
  e.val_rmse = number("val_rmse", kRequired);
  e.val_acc05 = number("val_acc05", kRequired);
  e.seconds = number("seconds", kRequired);
  e.train_aux_loss = number("train_aux_loss", 0.0);  // absent in runs from before auxiliary targets
  e.raw_val_rmse = number("raw_val_rmse", 0.0);      // absent in runs from before weight averages
  // Absent in runs from before stop 74.
  if (field("device") && !j["device"].is_string()) refuse("device", "a string");
  e.device = j.value("device", std::string());
  if (field("threads") && !j["threads"].is_number_integer()) refuse("threads", "an integer");
  e.threads = j.value("threads", 0);
  return e;
}

std::string LogTsv(const std::vector<EpochRecord>& log) {
  std::ostringstream s;
  // New columns go last: plot scripts read the others by number.
  s << "epoch\tlr\ttrain_loss\tval_loss\ttrain_rmse\tval_rmse\tval_acc05\tseconds\ttrain_aux_loss\traw_val_rmse"
       "\tdevice\tthreads\n"
    << std::setprecision(6);
  for (const EpochRecord& e : log) {
    s << e.epoch << "\t" << e.lr << "\t" << e.train_loss << "\t" << e.val_loss << "\t" << e.train_rmse << "\t"
      << e.val_rmse << "\t" << e.val_acc05 << "\t" << e.seconds << "\t" << e.train_aux_loss << "\t"
      << e.raw_val_rmse << "\t" << (e.device.empty() ? "-" : e.device) << "\t" << e.threads << "\n";
  }
  return s.str();
}

// A module's or an optimiser's state, written durably (fsync, rename, the folder synced).
template <typename T>
void SaveAtomically(T& object, const fs::path& path) {
  std::ostringstream bytes;
  torch::save(object, bytes);
  WriteFileAtomically(path, bytes.str());
}

// The best models of a run live in its checkpoint folder too (model.*, raw_model.*), so the
// epoch state.json names and the model.pt beside it always agree: model.pt was published before
// state.json, and a run stopped between the two kept a model.pt of an epoch its log did not show.
constexpr const char* kBestModelFiles[] = {"model.pt", "model.json", "raw_model.pt", "raw_model.json"};

// Publishes the best models a checkpoint folder holds as the run's model.pt / raw_model.pt (and
// their JSON); a checkpoint from before they were kept there holds none, and nothing is done.
void PublishBestModels(const fs::path& checkpoint, const fs::path& out) {
  for (const char* name : kBestModelFiles)
    if (fs::exists(checkpoint / name)) CopyFileAtomically((checkpoint / name).string(), (out / name).string());
}

// A run's state.json, parsed. Throws std::runtime_error naming it when it cannot be read.
nlohmann::json ReadState(const fs::path& state_path) {
  if (ExistsButNotARegularFile(state_path))
    throw std::runtime_error(state_path.string() + ": not a regular file (nothing to resume)");
  std::ifstream in(state_path);
  if (!in) throw std::runtime_error(state_path.string() + ": cannot open (nothing to resume)");
  nlohmann::json state;
  try {
    state = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(state_path.string() + ": not valid JSON: " + JsonErrorText(e));
  }
  // The type of every field a resume reads, checked here: they are read in many places after,
  // where a wrong one threw a bare "type must be string, but is number" naming neither the file
  // nor the field.
  if (!state.is_object()) throw std::runtime_error(state_path.string() + ": expected a JSON object");
  using Is = bool (nlohmann::json::*)() const noexcept;
  static const std::pair<const char*, std::pair<Is, const char*>> kFields[] = {
      {"epoch", {&nlohmann::json::is_number_integer, "an integer"}},
      {"seed", {&nlohmann::json::is_number_unsigned, "an unsigned integer"}},
      {"batch", {&nlohmann::json::is_number_integer, "an integer"}},
      {"epochs", {&nlohmann::json::is_number_integer, "an integer"}},
      {"lr_decay_epoch", {&nlohmann::json::is_number_integer, "an integer"}},
      {"aux_phase_bins", {&nlohmann::json::is_number_integer, "an integer"}},
      {"average_steps", {&nlohmann::json::is_number_integer, "an integer"}},
      {"weight_decay", {&nlohmann::json::is_number, "a number"}},
      {"grad_clip", {&nlohmann::json::is_number, "a number"}},
      {"lr", {&nlohmann::json::is_number, "a number"}},
      {"aux_tracks", {&nlohmann::json::is_number, "a number"}},
      {"weight_average", {&nlohmann::json::is_number, "a number"}},
      {"lr_schedule", {&nlohmann::json::is_string, "a string"}},
      {"checkpoint", {&nlohmann::json::is_string, "a string"}},
      {"validated_on", {&nlohmann::json::is_string, "a string"}},
      {"flip", {&nlohmann::json::is_boolean, "true or false"}},
      {"aux_world", {&nlohmann::json::is_boolean, "true or false"}},
      {"point_maps", {&nlohmann::json::is_boolean, "true or false"}},
      {"crop_scales", {&nlohmann::json::is_array, "an array of numbers"}},
      {"log", {&nlohmann::json::is_array, "an array of epochs"}},
      {"model", {&nlohmann::json::is_object, "the model's options (an object)"}},
  };
  for (const auto& [key, check] : kFields) {
    if (state.contains(key) && !(state[key].*check.first)())
      throw std::runtime_error(state_path.string() + ": field \"" + key + "\" must be " + check.second + ", got " +
                               state[key].dump());
  }
  if (state.contains("crop_scales"))
    for (const auto& v : state["crop_scales"])
      if (!v.is_number())
        throw std::runtime_error(state_path.string() + ": field \"crop_scales\" must be an array of numbers, got " +
                                 state["crop_scales"].dump());
  return state;
}

// The checkpoint folder `state` (out/state.json, parsed) names; see CheckpointDir.
fs::path CheckpointDirOf(const nlohmann::json& state, const fs::path& out) {
  const fs::path state_path = out / "state.json";
  // Runs written before checkpoint folders kept last.pt, ... beside state.json.
  if (!state.contains("checkpoint")) return out;
  if (!state["checkpoint"].is_string())
    throw std::runtime_error(state_path.string() + ": field \"checkpoint\" must be a folder name");
  const fs::path dir = out / state["checkpoint"].get<std::string>();
  if (!fs::is_directory(dir))
    throw std::runtime_error(state_path.string() + ": its checkpoint " + dir.string() + " is missing");
  return dir;
}

}  // namespace

fs::path CheckpointDir(const fs::path& out) { return CheckpointDirOf(ReadState(out / "state.json"), out); }

namespace {

// Whether `name` is one of a run's checkpoint folders, "checkpoint-e" and the epoch's digits, or
// the temporary one it is built in (".checkpoint-eNNNN.tmp"). Exactly: a prefix took a user's
// copy of a good checkpoint ("checkpoint-e0012-keep") at the next epoch.
bool IsCheckpointName(const std::string& name) {
  const bool hidden = !name.empty() && name[0] == '.';
  std::string rest = name.substr(hidden ? 1 : 0);
  if (hidden) {
    if (rest.size() < 4 || rest.compare(rest.size() - 4, 4, ".tmp") != 0) return false;
    rest.resize(rest.size() - 4);
  }
  const std::string prefix = "checkpoint-e";
  if (rest.rfind(prefix, 0) != 0 || rest.size() < prefix.size() + 4) return false;
  return std::all_of(rest.begin() + prefix.size(), rest.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// Deletes what a run writes in `out` (state, checkpoints, models, log, learning curve), leaving
// anything else there alone.
void RemoveRun(const fs::path& out) {
  for (const auto& entry : fs::directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    // Exact names (and their temporaries): a prefix took a user's "last_eval/" or "model.onnx".
    static const std::set<std::string> kFiles = {
        "state.json", "log.tsv",       "last.pt",        "last_optim.pt",          "last_average.pt",
        "model.pt",   "model.json",    "raw_model.pt",   "raw_model.json",         "learning_curve.png",
        "learning_curve.png.dat",      "learning_curve.png.gp",  "learning_curve.png.gp.err"};
    const size_t tmp = name.find(".tmp-");
    const std::string base = tmp == std::string::npos ? name : name.substr(0, tmp);
    const bool run_file = kFiles.count(base) > 0 || IsCheckpointName(name);
    if (run_file) fs::remove_all(entry.path());
  }
}

// A fingerprint of the clips a run trains and validates on (names, splits, targets), so a resume
// against another dataset is refused: the label scaling comes from the state, the clips from
// --data, and a regenerated folder silently trained the run on other clips. Folder paths are left
// out, so a dataset moved elsewhere still resumes.
std::string DataFingerprint(const std::vector<ClipInfo>& train, const std::vector<ClipInfo>& val) {
  uint64_t h = 1469598103934665603ULL;  // FNV-1a, 64 bit
  auto add = [&h](const std::string& text) {
    for (unsigned char c : text) {
      h ^= c;
      h *= 1099511628211ULL;
    }
    h ^= 0xff;  // separator
    h *= 1099511628211ULL;
  };
  // In name order: a recorded dataset's index moves a replaced clip to its end, so the same
  // clips can be listed in another order.
  for (const auto* split : {&train, &val}) {
    std::vector<std::string> entries;
    for (const ClipInfo& c : *split) {
      char target[32];
      std::snprintf(target, sizeof target, "%.17g", c.wind_speed);
      entries.push_back(c.name + '\n' + c.split + '\n' + target);
    }
    std::sort(entries.begin(), entries.end());
    add("split");
    for (const std::string& e : entries) add(e);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

// The model options a resumed run must be given as it started: they shape the network, and the
// state's were used silently whatever these said (--model resnet18 --width 8 resumed an SDN of
// width 4 without a word).
void RefuseChangedModelOnResume(const fs::path& state_path, const ModelConfig& ran, const ModelConfig& given) {
  const nlohmann::json a = ToJson(ran), b = ToJson(given);
  static const std::pair<const char*, const char*> kOptions[] = {
      {"arch", "--model"},           {"frames", "--frames"},         {"input_size", "--input-size"},
      {"width", "--width"},          {"k", "--k"},                   {"include_dc", "--include-dc"},
      {"dft_size", "--dft-size"},    {"local_peaks", "--local-peaks"}, {"dropout", "--dropout"},
      {"phase_steps", "--phase-steps"}, {"phase_step_far", "--phase-step-far"}, {"mode_shape", "--mode-shape"},
      {"still_floor", "--still-floor"}, {"spectral_pool", "--spectral-pool"}, {"stem_pool", "--no-stem-pool"}, {"coord_maps", "--coord-maps"},
      {"flow", "--flow"},            {"flow_size", "--flow-size"},   {"colour", "--colour"},
      {"head_hidden", "--head-hidden"}, {"frame_channels", "--frame-channels"}, {"mean_map", "--mean-map"}};
  for (const auto& [key, flag] : kOptions) {
    if (a[key] == b[key]) continue;
    throw std::runtime_error(state_path.string() + ": the run's model field \"" + key + "\" is " + a[key].dump() +
                             ", these options give " + b[key].dump() + " (" + flag +
                             "); resume with the model options the run started with");
  }
}

// The step schedule's last epoch at the full rate: lr_decay_epoch, or half the epochs for -1.
int StepDecayEpoch(const TrainOptions& o) { return o.lr_decay_epoch < 0 ? std::max(1, o.epochs / 2) : o.lr_decay_epoch; }

// An option's value as the refusal below names it: a flag on or off, a number as it is.
std::string OptionValue(bool v) { return v ? "on" : "off"; }
std::string OptionValue(const std::string& v) { return v; }
template <typename T>
std::string OptionValue(T v) {
  return std::to_string(v);
}

// On a resume, refuses an option whose value differs from the one the run started with (`ran`,
// from its state.json at state_path), naming the flag.
template <typename T>
void RefuseChangedOnResume(const fs::path& state_path, const std::string& flag, T ran, T given) {
  if (ran == given) return;
  throw std::runtime_error(state_path.string() + ": the run trained with " + flag + " " + OptionValue(ran) +
                           ", these options give " + OptionValue(given) + "; resume with the " + flag +
                           " the run started with");
}

// A network's validation: mean WindLoss (normalised units) and metrics in m/s.
struct Validation {
  double loss = 0;
  Metrics metrics;
};

// The validation split as the trunk reads it: each batch's trunk input images (on the CPU) and
// labels [m/s]. Validation reads every clip the same way each epoch (no augmentation) and
// TrunkInput has no weights, so the images of the first validation serve every later one, the
// same to the bit, without the spectral layer's cost (a third of a validation batch at 96 px).
struct ValidationImages {
  std::vector<at::Tensor> images, speeds;
};

// Validates `model` (put in eval mode) on `val` in batches of `batch`, as evaluation reads clips.
// With `kept`: reads the images kept there when it holds them, else computes them from the files
// and keeps them there.
Validation Validate(WindNet& model, const std::vector<ClipInfo>& val, int batch, const SampleOptions& options,
                    const ModelConfig& config, const at::Device& device, ValidationImages* kept,
                    const std::function<void(int)>& clips_done = {}) {
  model->eval();
  at::NoGradGuard no_grad;
  const FullFloat32Scope full_float32;  // on a GPU: pick the epoch by the network eval and the node run
  const float mean = static_cast<float>(config.label_mean), inv_std = static_cast<float>(1.0 / config.label_std);
  std::vector<size_t> all(val.size());
  std::iota(all.begin(), all.end(), 0);
  std::vector<double> truth, predicted;
  double loss = 0;
  const bool reuse = kept && !kept->images.empty();
  for (size_t b = 0, i = 0; b < all.size(); b += batch, ++i) {
    at::Tensor images, speeds;
    if (reuse) {
      images = kept->images.at(i).to(device);
      speeds = kept->speeds.at(i);
    } else {
      Batch clips = LoadBatch(val, all, b, std::min(all.size(), b + batch), options, 0, nullptr, nullptr);
      images = model->TrunkInput(clips.clips.to(device));
      speeds = clips.speeds;
      if (kept) {
        kept->images.push_back(images.to(at::kCPU));
        kept->speeds.push_back(speeds);
      }
    }
    at::Tensor y = (speeds - mean) * inv_std;
    at::Tensor out = model->ForwardImages(images, speeds.size(0)).wind.to(at::kCPU);
    loss += WindLoss(out, y).item<double>() * y.size(0);
    at::Tensor speed = (out.select(1, 0) * config.label_std + config.label_mean).to(at::kDouble).contiguous();
    at::Tensor label = speeds.to(at::kDouble).contiguous();
    for (int64_t i = 0; i < y.size(0); ++i) {
      predicted.push_back(ClampSpeed(speed.data_ptr<double>()[i]));  // as eval and the node read it
      truth.push_back(label.data_ptr<double>()[i]);
    }
    if (clips_done) clips_done(static_cast<int>(truth.size()));
  }
  return {loss / std::max<size_t>(val.size(), 1), ComputeMetrics(truth, predicted)};
}

// The [points, 2] means (or stds) of the points' window-mean (u, v) targets, TrackTargets' columns
// kTargetsPerPoint · p and kTargetsPerPoint · p + 1 of `scale`.
at::Tensor PointScale(const TargetScale& scale, int points, bool std) {
  const std::vector<float>& values = std ? scale.std : scale.mean;
  const std::vector<float> blocks(values.begin(), values.begin() + static_cast<size_t>(points) * kTargetsPerPoint);
  return at::tensor(blocks).view({points, kTargetsPerPoint}).narrow(1, 0, 2).contiguous();
}

}  // namespace

// torch::load onto the CPU, its errors (a checkpoint cut short: "PytorchStreamReader failed
// reading zip archive", with a backtrace) prefixed with the file and what to do.
template <typename T>
void LoadNamingTheFile(T& into, const fs::path& file) {
  try {
    torch::load(into, file.string(), at::Device(at::kCPU));
  } catch (const c10::Error& e) {
    throw std::runtime_error(file.string() + ": cannot read this checkpoint (" + e.what_without_backtrace() +
                             "); a run stopped while writing it? Copy out the run's model.pt and the checkpoints' "
                             "model.pt you want to keep, then train again with --overwrite, which deletes them");
  }
}

double LearningRateAt(const TrainOptions& o, int epoch) {
  if (o.lr_schedule == "step") {
    return epoch > StepDecayEpoch(o) ? o.lr / o.lr_decay_factor : o.lr;
  }
  if (o.lr_schedule == "cosine") {
    const double progress = static_cast<double>(epoch - 1) / std::max(1, o.epochs);
    return o.lr * 0.5 * (1.0 + std::cos(M_PI * std::clamp(progress, 0.0, 1.0)));
  }
  throw std::invalid_argument("lr_schedule must be step or cosine, got \"" + o.lr_schedule + "\"");
}

void ValidateTrainOptions(const TrainOptions& o) {
  if (o.device != "cpu" && o.device != "cuda" && o.device != "auto") {
    throw std::invalid_argument("device must be cpu, cuda or auto, got \"" + o.device + "\"");
  }
  if (o.epochs < 1 || o.batch < 1) throw std::invalid_argument("epochs and batch must be at least 1");
  // Batch normalisation normalises each channel over the batch: one clip leaves nothing to
  // normalise over once the trunk's feature map is 1x1, and libtorch failed mid-epoch with a
  // backtrace naming no option.
  if (o.batch < 2 && !o.init_only)
    throw std::invalid_argument("--batch must be at least 2 to train (batch normalisation needs two clips), got " +
                                std::to_string(o.batch));
  if (o.crop_scales.empty()) throw std::invalid_argument("crop_scales: expected at least one scale in (0, 1]");
  for (double s : o.crop_scales) {
    if (!(s > 0 && s <= 1)) {
      throw std::invalid_argument("crop_scales: each scale must lie in (0, 1], got " + FormattedNumber(s));
    }
  }
  if (o.lr_schedule != "step" && o.lr_schedule != "cosine") {
    throw std::invalid_argument("lr schedule must be step or cosine, got \"" + o.lr_schedule + "\"");
  }
  // NaN passes CLI11's range checks; these ran a run to its end (NaN dropout, gradient clip), or
  // failed deep in libtorch with a backtrace naming no option (NaN lr, weight decay).
  const auto require = [](bool ok, const char* option, const char* expected, double value) {
    if (!ok) throw std::invalid_argument(std::string(option) + " must be " + expected + ", got " + FormattedNumber(value));
  };
  require(std::isfinite(o.lr) && o.lr > 0 && o.lr <= 10, "--lr", "in (0, 10]", o.lr);
  require(std::isfinite(o.lr_decay_factor) && o.lr_decay_factor > 0, "--lr-decay-factor", "finite and > 0",
          o.lr_decay_factor);
  require(o.lr_decay_epoch >= -1, "--lr-decay-epoch", ">= 0 (or -1: --epochs / 2)", o.lr_decay_epoch);
  require(std::isfinite(o.weight_decay) && o.weight_decay >= 0, "--weight-decay", "finite and >= 0", o.weight_decay);
  require(std::isfinite(o.grad_clip), "--grad-clip", "finite (0: off, < 0: the seed's)", o.grad_clip);
  require(std::isfinite(o.aux_tracks) && o.aux_tracks >= 0, "--aux-tracks", "finite and >= 0", o.aux_tracks);
  require(o.weight_average >= 0 && o.weight_average < 1, "--weight-average", "in [0, 1)", o.weight_average);
  require(o.model.dropout >= 0 && o.model.dropout < 1, "--dropout", "in [0, 1)", o.model.dropout);
  if (o.data.empty() && !o.init_only) throw std::invalid_argument("training needs --data");
  if (!o.resume && !o.overwrite) {
    for (const char* file : {"state.json", "model.pt"}) {
      if (fs::exists(o.out / file))
        throw std::invalid_argument((o.out / file).string() + ": a run is already in " + o.out.string() +
                                    "; --resume continues it, --overwrite starts it again (or choose another --out)");
    }
  }
  // --init-only writes an untrained model.pt and stops; with --resume it wrote the last epoch's
  // raw weights over the run's best model and called them untrained.
  if (o.init_only && o.resume)
    throw std::invalid_argument("--init-only and --resume cannot be combined: --init-only writes an untrained model, "
                                "--resume continues a run's training");
  // The model's shape (peaks a DFT of --frames offers, frame channels): "--frames 4" with the
  // default --k 3 failed naming only the configuration's field "k". A resumed run's are its own.
  if (!o.resume) {
    ModelConfig config = o.model;
    config.channels = config.ChannelsForInput();
    try {
      ModelConfigFromJson(ToJson(config), "the model options");
    } catch (const std::exception& e) {
      throw std::invalid_argument(std::string(e.what()) +
                                  " (its fields are the options of those names: \"k\" is --k, \"frame_channels\" "
                                  "--frame-channels)");
    }
  }
}

TrainResult Train(const TrainOptions& o) {
  // Flush denormals to zero: weight decay drives many weights and activations towards zero, and
  // denormal floats made CPU training epochs 3x slower after ~10 epochs. Set before the intra-op
  // threads exist: new threads inherit this thread's floating-point mode.
  at::globalContext().setFlushDenormal(true);
  if (o.threads > 0) at::set_num_threads(o.threads);
  ValidateTrainOptions(o);
  if (o.device == "cuda" && !torch::cuda::is_available()) {
    throw std::runtime_error("device cuda requested but libtorch finds no CUDA device");
  }
  const at::Device device = (o.device != "cpu" && torch::cuda::is_available()) ? at::Device(at::kCUDA)
                                                                                 : at::Device(at::kCPU);
  TrainResult result;
  result.device = device.is_cuda() ? "cuda" : "cpu";
  result.model = o.out / "model.pt";

  std::vector<ClipInfo> train, val;
  if (!o.data.empty()) {
    const Dataset dataset = ReadDataset(o.data);
    train = SelectSplit(dataset, "train");
    val = SelectSplit(dataset, "val");
    // In name order, whatever order the index lists them in: the epoch's shuffle and each clip's
    // augmentation seed are positions in the split, so a dataset whose index lists the same clips
    // in another order (a recorded one moves a replaced clip to its end) trained another run, and
    // a resume on it (which DataFingerprint accepts) did not repeat the uninterrupted run.
    // make-dataset's and the toy dataset's indexes are already in this order (BuildIndex sorts the
    // names the same way), so their runs are unchanged.
    for (std::vector<ClipInfo>* split : {&train, &val})
      std::sort(split->begin(), split->end(), [](const ClipInfo& a, const ClipInfo& b) { return a.name < b.name; });
    if (!o.init_only && train.empty()) {
      throw std::runtime_error((o.data / "index.json").string() + ": no examples in split train");
    }
    // Batch normalisation needs two clips in a batch (the check of --batch above); a split of one
    // trains batches of one, and libtorch failed mid-epoch naming no option.
    if (!o.init_only && train.size() < 2) {
      throw std::runtime_error((o.data / "index.json").string() + ": split train has " +
                               std::to_string(train.size()) +
                               " clip; training needs at least 2 (batch normalisation normalises over a batch)");
    }
    // A dataset without a validation split validates, and chooses model.pt, on the train split:
    // said in the result (the CLI prints it) and in state.json, so its "validation RMSE" is not
    // read as a held-out score.
    if (val.empty()) {
      val = train;
      result.validated_on = "train (the dataset has no val split)";
    }
  }

  ModelConfig config = o.model;
  CheckClipsSuitModel(train, config.frame_rate, config.colour, config.frames);
  CheckClipsSuitModel(val, config.frame_rate, config.colour, config.frames);
  config.channels = config.ChannelsForInput();  // greyscale, as the seed (+ flow x, y), or Y Cr Cb
  if (!train.empty()) {
    double sum = 0, sum2 = 0;
    for (const ClipInfo& c : train) {
      sum += c.wind_speed;
      sum2 += c.wind_speed * c.wind_speed;
    }
    config.label_mean = sum / train.size();
    const double var = sum2 / train.size() - config.label_mean * config.label_mean;
    config.label_std = var > 1e-12 ? std::sqrt(var) : 1.0;
  }
  // The checks every model.json gets when read, before any work: a model eval could not load
  // (or one of 10^12 weights) used to be trained first.
  if (!o.resume) ModelConfigFromJson(ToJson(config), "the model options");
  const fs::path state_path = o.out / "state.json";
  nlohmann::json state;
  if (o.resume) {
    state = ReadState(state_path);
    try {
      config = ModelConfigFromJson(state.at("model"), state_path.string());
      ModelConfig given = o.model;
      if (o.still_floor_default) given.still_floor = config.still_floor;
      RefuseChangedModelOnResume(state_path, config, given);
      const nlohmann::json& log = state.at("log");
      for (size_t i = 0; i < log.size(); ++i)
        result.log.push_back(EpochFromJson(log[i], state_path.string() + ": log[" + std::to_string(i) + "]"));
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(state_path.string() + ": " + JsonErrorText(e));
    }
    // The run resumes after its log's last epoch: an "epoch" that says otherwise (an edited or
    // mixed-up state.json) resumed without a word.
    if (!state.contains("epoch"))
      throw std::runtime_error(state_path.string() + ": field \"epoch\" is missing (nothing to resume from)");
    const int64_t said = state["epoch"].get<int64_t>();
    bool numbered = said == static_cast<int64_t>(result.log.size());
    for (size_t i = 0; i < result.log.size(); ++i) numbered = numbered && result.log[i].epoch == static_cast<int>(i) + 1;
    if (!numbered)
      throw std::runtime_error(state_path.string() + ": field \"epoch\" is " + std::to_string(said) + ", but its log holds " +
                               std::to_string(result.log.size()) + " epochs numbered from 1 (a state.json edited or " +
                               "mixed up; nothing to resume from)");
    // A resumed run must keep the schedule it ran under: a cosine run resumed with other --epochs
    // (or any run with another --lr, --lr-schedule or --lr-decay-epoch) would silently become a
    // different run from the one its log describes.
    // (Runs that record their schedule are checked against it below, every epoch of it.)
    for (const EpochRecord& e : result.log) {
      if (state.contains("epochs")) break;
      const double expected = LearningRateAt(o, e.epoch);
      if (std::abs(expected - e.lr) > 1e-9 * std::max(std::abs(e.lr), 1e-12)) {
        std::ostringstream what;
        what << state_path.string() << ": epoch " << e.epoch << " ran at learning rate " << e.lr
             << ", but these options give " << expected << " there (--lr-schedule " << o.lr_schedule
             << ", --epochs " << o.epochs << "); resume with the --lr, --lr-schedule, --epochs and "
             << "--lr-decay-epoch the run started with";
        throw std::runtime_error(what.str());
      }
    }
    // Runs from before crop_scales was recorded used the seed's scales (the default).
    const std::vector<double> ran_with =
        state.contains("crop_scales") ? state["crop_scales"].get<std::vector<double>>()
                                      : TrainOptions().crop_scales;
    if (ran_with != o.crop_scales) {
      throw std::runtime_error(state_path.string() + ": the run trained with crop scales " +
                               nlohmann::json(ran_with).dump() + ", these options give " +
                               nlohmann::json(o.crop_scales).dump() +
                               "; resume with the --crop-scales the run started with");
    }
  }
  // Auxiliary track targets: read (and their head sized) before the network is built.
  if (!(o.aux_tracks >= 0)) throw std::runtime_error("aux_tracks: the loss weight must be >= 0");
  if (o.resume) RefuseChangedOnResume(state_path, "--aux-tracks", state.value("aux_tracks", 0.0), o.aux_tracks);
  if (o.resume) RefuseChangedOnResume(state_path, "--no-flip", !state.value("flip", true), !o.flip);
  config.flips_in_training = o.flip;
  if (o.aux_phase_bins < 0 || o.aux_phase_bins > kTrackBins || (o.aux_phase_bins > 0 && o.aux_tracks <= 0))
    throw std::runtime_error("aux_phase_bins: must be in [0, " + std::to_string(kTrackBins) +
                             "], and above 0 only with an auxiliary loss (--aux-tracks W > 0)");
  if (o.resume) RefuseChangedOnResume(state_path, "--aux-phases", state.value("aux_phase_bins", 0), o.aux_phase_bins);
  if (o.aux_world && o.aux_tracks <= 0)
    throw std::runtime_error("aux_world: the points' positions are regressed only with an auxiliary loss "
                             "(--aux-tracks W > 0)");
  if (o.resume) RefuseChangedOnResume(state_path, "--aux-world", state.value("aux_world", false), o.aux_world);
  if (o.point_maps && o.aux_tracks <= 0)
    throw std::runtime_error("point_maps: the points are found on maps only with an auxiliary loss (--aux-tracks W > 0)");
  if (o.resume) RefuseChangedOnResume(state_path, "--point-maps", state.value("point_maps", false), o.point_maps);
  if (o.resume) {
    RefuseChangedOnResume(state_path, "--weight-average", state.value("weight_average", 0.0), o.weight_average);
    // The sampling order, batches and optimiser a resumed run repeats (runs before 2026-12-05
    // recorded only the seed).
    if (state.contains("seed")) RefuseChangedOnResume(state_path, "--seed", state["seed"].get<uint64_t>(), o.seed);
    if (state.contains("batch")) RefuseChangedOnResume(state_path, "--batch", state["batch"].get<int>(), o.batch);
    if (state.contains("weight_decay"))
      RefuseChangedOnResume(state_path, "--weight-decay", state["weight_decay"].get<double>(), o.weight_decay);
    if (state.contains("grad_clip"))
      RefuseChangedOnResume(state_path, "--grad-clip", state["grad_clip"].get<double>(), o.grad_clip);
    // The schedule itself (recorded since 2026-12-05): the log's rates cannot refuse a cosine run
    // resumed after one epoch with other --epochs, nor a step run resumed with other --epochs
    // before its decay, and either would then run another schedule than the one it started.
    if (state.contains("lr")) RefuseChangedOnResume(state_path, "--lr", state["lr"].get<double>(), o.lr);
    if (state.contains("lr_schedule"))
      RefuseChangedOnResume(state_path, "--lr-schedule", state["lr_schedule"].get<std::string>(), o.lr_schedule);
    // Other --epochs or --lr-decay-epoch only where they leave every epoch's rate as the run's own
    // schedule gives it (a step run may go on for longer with its decay epoch given, its default
    // one resolved from the epochs it started with; a cosine run may not).
    if (state.contains("epochs") && state.contains("lr_decay_epoch")) {
      TrainOptions started = o;
      started.epochs = state["epochs"].get<int>();
      started.lr_decay_epoch = state["lr_decay_epoch"].get<int>();
      // The started schedule read past its end: a step run's rate stays decayed, a cosine run's
      // is 0 (so a cosine run is never extended).
      for (int e = 1; e <= o.epochs; ++e) {
        if (LearningRateAt(started, e) == LearningRateAt(o, e)) continue;
        std::ostringstream what;
        what << state_path.string() << ": the run started with --epochs " << started.epochs << ", whose "
             << o.lr_schedule << " schedule runs epoch " << e << " at " << LearningRateAt(started, e)
             << "; --epochs " << o.epochs << " --lr-decay-epoch " << o.lr_decay_epoch << " give "
             << LearningRateAt(o, e)
             << " (resume with the --epochs the run started with, or extend a step run with --lr-decay-epoch "
             << StepDecayEpoch(started)
             << ", its decay epoch)";
        throw std::runtime_error(what.str());
      }
    }
  }
  const std::string data_fingerprint = DataFingerprint(train, val);
  if (o.resume && state.contains("data_fingerprint") && state["data_fingerprint"] != data_fingerprint) {
    throw std::runtime_error(state_path.string() + ": the run trained on other clips than " + o.data.string() +
                             " holds now (their names, splits or wind speeds differ: another or a regenerated "
                             "dataset); resume with the --data it started with, or start a new run");
  }
  std::unique_ptr<AuxTargets> aux;
  if (o.aux_tracks > 0 && !train.empty()) {
    aux = std::make_unique<AuxTargets>(ReadAuxTargets(train, config.Sampling(), o.aux_phase_bins, o.aux_world));
    if (o.resume && config.aux_outputs != aux->outputs()) {
      throw std::runtime_error(state_path.string() + ": the run's auxiliary head has " +
                               std::to_string(config.aux_outputs) + " outputs, the dataset's tracks give " +
                               std::to_string(aux->outputs()));
    }
    config.aux_outputs = aux->outputs();
    config.point_maps = o.point_maps ? aux->tracks.front().points() : 0;
  }
  at::manual_seed(o.seed);
  WindNet net(config);
  // The maps' positions are standardised as the targets are; on resume the buffers come with the weights.
  if (config.point_maps > 0) net->SetPointScale(PointScale(aux->scale, config.point_maps, false),
                                                PointScale(aux->scale, config.point_maps, true));
  torch::optim::Adam optimizer(net->parameters(), torch::optim::AdamOptions(o.lr).weight_decay(o.weight_decay));
  // The checkpoint state.json names (resume): the weights, their average and Adam's moments of
  // its epoch, whatever a run stopped while saving the next one left beside them.
  const fs::path resume_from = o.resume ? CheckpointDirOf(state, o.out) : fs::path();
  if (o.resume) {
    // Loaded onto the CPU whatever device wrote them, then moved with the network.
    LoadNamingTheFile(net, resume_from / "last.pt");
    LoadNamingTheFile(optimizer, resume_from / "last_optim.pt");
  }
  // The weight average starts at the initial weights and lives beside them on the device.
  WindNet average{nullptr};
  int64_t average_steps = 0;
  if (o.weight_average > 0) {
    average = WindNet(config);
    CopyWeights(*net, *average);
    if (o.resume) {
      LoadNamingTheFile(average, resume_from / "last_average.pt");
      average_steps = state.value("average_steps", int64_t{0});
    }
    average->to(device);
  }
  net->to(device);
  for (auto& entry : optimizer.state()) {  // Adam's moments live beside their parameters
    auto& state = static_cast<torch::optim::AdamParamState&>(*entry.second);
    state.exp_avg(state.exp_avg().to(device));
    state.exp_avg_sq(state.exp_avg_sq().to(device));
    if (state.max_exp_avg_sq().defined()) state.max_exp_avg_sq(state.max_exp_avg_sq().to(device));
  }
  const SampleOptions val_options = config.Sampling();
  SampleOptions train_options = config.Sampling();
  train_options.augment = true;
  train_options.crop_scales = o.crop_scales;
  train_options.flip = o.flip;
  // With the frames cached, the validation split's files are read once, by the first validation,
  // whose trunk input images serve every later one: a frame cache of it would be read only once.
  // Checked and read before the run folder is touched: --overwrite deleted the old run and then
  // refused --cache-frames.
  std::unique_ptr<FrameCache> train_cache;
  std::unique_ptr<ValidationImages> val_images;
  if (o.cache_frames && !o.init_only) {
    val_images = std::make_unique<ValidationImages>();
    std::string why;
    for (const ClipInfo& c : train) {
      if (!FrameCache::Exact(train_options, c, &why)) {
        throw std::runtime_error("--cache-frames would change the training samples: " + why);
      }
    }
    train_cache = std::make_unique<FrameCache>(train, config.input_size, config.colour);
  }
  // Made once the options, the data and the network are known good: a refusal used to leave an
  // empty folder.
  fs::create_directories(o.out);
  // --overwrite starts again here, not when epoch 1 replaces the files: a run that failed in its
  // first epoch left the old run's state for --resume to continue, and files the new run does not
  // write (raw_model.* without a weight average) stayed for good.
  if (o.overwrite && !o.resume) RemoveRun(o.out);
  if (o.init_only) {
    SaveWindNet(net, result.model);
    return result;
  }
  // A run stopped after publishing a model but before its state.json: the checkpoint's models are
  // the ones its log describes.
  if (o.resume) PublishBestModels(resume_from, o.out);

  result.best_val_rmse = std::numeric_limits<double>::infinity();
  double best_raw_val_rmse = std::numeric_limits<double>::infinity();
  for (const EpochRecord& e : result.log) {
    result.best_val_rmse = std::min(result.best_val_rmse, e.val_rmse);
    best_raw_val_rmse = std::min(best_raw_val_rmse, e.raw_val_rmse);
  }
  // The seed clips gradients (max norm 10) for its recurrent models only.
  const double grad_clip = o.grad_clip >= 0 ? o.grad_clip : (config.arch == "lstm" ? 10.0 : 0.0);
  const float mean = static_cast<float>(config.label_mean), inv_std = static_cast<float>(1.0 / config.label_std);

  for (int epoch = static_cast<int>(result.log.size()) + 1; epoch <= o.epochs; ++epoch) {
    const auto start = std::chrono::steady_clock::now();
    EpochRecord record;
    record.epoch = epoch;
    record.lr = LearningRateAt(o, epoch);
    record.device = result.device;
    record.threads = at::get_num_threads();
    for (auto& group : optimizer.param_groups()) {
      static_cast<torch::optim::AdamOptions&>(group.options()).lr(record.lr);
    }
    // The epoch's order and augmentations depend only on (seed, epoch): a resumed run repeats them.
    // So do torch's own draws (dropout's masks): its generator is not in the checkpoint, so it is
    // seeded afresh each epoch (a resumed run drew epoch 1's masks again).
    at::manual_seed(o.seed * 104729 + static_cast<uint64_t>(epoch));
    std::vector<size_t> order(train.size());
    std::iota(order.begin(), order.end(), 0);
    std::mt19937_64 rng(o.seed * 7919 + epoch);
    std::shuffle(order.begin(), order.end(), rng);
    const uint64_t seed_base = (o.seed * 1000003ULL + epoch) * 1000003ULL;
    // A last batch of one cannot be batch-normalised at 1x1 spatial size; drop it.
    size_t usable = order.size();
    if (usable % o.batch == 1 && usable > 1) --usable;
    const int steps = static_cast<int>((usable + o.batch - 1) / o.batch);
    net->train();
    double loss_sum = 0, se_sum = 0, aux_sum = 0;
    size_t seen = 0;
    auto load = [&](size_t b) {
      return std::async(std::launch::async, LoadBatch, std::cref(train), std::cref(order), b,
                        std::min(usable, b + o.batch), std::cref(train_options), seed_base, train_cache.get(),
                        aux.get());
    };
    // Step 0 opens the epoch before its first batch loads, so a reader's clock (a progress bar's
    // rate and time left) counts that batch too.
    if (o.progress) o.progress({epoch, o.epochs, 0, steps, 0});
    std::future<Batch> next = load(0);
    for (int step = 0; step < steps; ++step) {
      Batch batch = next.get();
      const size_t following = static_cast<size_t>(step + 1) * o.batch;
      if (following < usable) next = load(following);  // decode the next batch while this one trains
      at::Tensor x = batch.clips.to(device), y = ((batch.speeds - mean) * inv_std).to(device);
      optimizer.zero_grad();
      const WindNetImpl::Outputs outputs = net->ForwardWithAux(x);
      const at::Tensor& out = outputs.wind;
      const at::Tensor wind_loss = WindLoss(out, y);
      at::Tensor loss = wind_loss;
      if (aux) {
        at::Tensor aux_loss = AuxLoss(outputs.aux, batch.aux.to(device));
        aux_sum += aux_loss.item<double>() * x.size(0);
        loss = loss + o.aux_tracks * aux_loss;
      }
      // One non-finite batch turns every weight NaN through Adam, and the run went on for hours to
      // end "finished"; the last checkpoint is still the previous epoch's.
      const double loss_value = loss.item<double>();
      if (!std::isfinite(loss_value)) {
        std::ostringstream what;
        what << "epoch " << epoch << ", step " << step + 1 << " of " << steps << ": the training loss is "
             << loss_value << " (a target or input not finite, or a learning rate too high); stopped before it "
             << "reached the weights. " << (epoch > 1 ? "The checkpoint of epoch " + std::to_string(epoch - 1) +
                                                            " is intact, but a resume repeats these batches: "
                                                      : std::string("No epoch was saved: "))
             << "start a new run with a lower --lr (or --grad-clip)";
        throw std::runtime_error(what.str());
      }
      loss.backward();
      if (grad_clip > 0) torch::nn::utils::clip_grad_norm_(net->parameters(), grad_clip);
      optimizer.step();
      if (!average.is_empty()) BlendWeights(*net, *average, AverageDecayAt(o.weight_average, average_steps++));
      const int64_t n = x.size(0);
      // The wind's loss alone, as validation's (the auxiliary loss has its own column).
      loss_sum += wind_loss.item<double>() * n;
      se_sum += ((out.select(1, 0).detach() - y).square().sum()).item<double>() * config.label_std * config.label_std;
      seen += n;
      if (o.progress) o.progress({epoch, o.epochs, step + 1, steps, loss_sum / seen});
    }
    record.train_loss = loss_sum / std::max<size_t>(seen, 1);
    record.train_rmse = std::sqrt(se_sum / std::max<size_t>(seen, 1));
    record.train_aux_loss = aux_sum / std::max<size_t>(seen, 1);

    // Validation: evaluation preprocessing, no augmentation; the average's, when there is one.
    // With the frames cached the trunk's input images are kept after the first validation.
    // Validation shows on the epoch's bar (it takes minutes on a large split, after the bar is full).
    const int val_total = static_cast<int>(val.size()) * (average.is_empty() ? 1 : 2);
    const double train_loss = loss_sum / std::max<size_t>(seen, 1);
    auto val_progress = [&](int offset) {
      return [&, offset](int done) {
        if (o.progress) o.progress({epoch, o.epochs, steps, steps, train_loss, offset + done, val_total});
      };
    };
    const Validation raw =
        Validate(net, val, o.batch, val_options, config, device, val_images.get(), val_progress(0));
    const Validation chosen =
        average.is_empty() ? raw
                           : Validate(average, val, o.batch, val_options, config, device, val_images.get(),
                                      val_progress(static_cast<int>(val.size())));
    record.val_loss = chosen.loss;
    record.val_rmse = chosen.metrics.rmse;
    record.val_acc05 = chosen.metrics.acc05;
    if (!average.is_empty()) record.raw_val_rmse = raw.metrics.rmse;
    record.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.log.push_back(record);

    // Checkpoint: weights on the CPU so any machine can load them.
    net->to(at::kCPU);
    if (!average.is_empty()) average->to(at::kCPU);
    // The epoch's checkpoint goes into a folder of its own, made whole under a hidden name and
    // renamed; state.json, written after it, names it. A run stopped anywhere in between resumes
    // from the checkpoint state.json names, never from weights of one epoch with another's
    // optimiser state and log (which the files last.pt, ... rewritten in place allowed). The best
    // models go in it too (this epoch's if better, else the previous checkpoint's), and are
    // published as model.pt / raw_model.pt only once state.json names it.
    char checkpoint_name[32];
    std::snprintf(checkpoint_name, sizeof checkpoint_name, "checkpoint-e%04d", epoch);
    const fs::path checkpoint = o.out / checkpoint_name;
    const fs::path checkpoint_tmp = o.out / ("." + std::string(checkpoint_name) + ".tmp");
    fs::remove_all(checkpoint_tmp);
    fs::create_directories(checkpoint_tmp);
    const fs::path previous = state.contains("checkpoint") && state["checkpoint"].is_string()
                                  ? o.out / state["checkpoint"].get<std::string>()
                                  : fs::path();
    auto carry_over = [&](const char* weights, const char* json) {
      for (const char* name : {weights, json}) {
        if (previous.empty() || !fs::exists(previous / name)) continue;
        // Unchanged: no copy. A copy (no hard links there) is synced like every file of the
        // checkpoint: the rename below publishes the folder, and a crash must not leave it with a
        // model cut short.
        LinkOrCopyFile((previous / name).string(), (checkpoint_tmp / name).string());
      }
    };
    const bool better = record.val_rmse < result.best_val_rmse;
    if (better) {
      result.best_val_rmse = record.val_rmse;
      SaveWindNet(average.is_empty() ? net : average, checkpoint_tmp / "model.pt");
    } else {
      carry_over("model.pt", "model.json");
    }
    const bool raw_better = !average.is_empty() && record.raw_val_rmse < best_raw_val_rmse;
    if (raw_better) {
      best_raw_val_rmse = record.raw_val_rmse;
      SaveWindNet(net, checkpoint_tmp / "raw_model.pt");
    } else if (!average.is_empty()) {
      carry_over("raw_model.pt", "raw_model.json");
    }
    SaveAtomically(net, checkpoint_tmp / "last.pt");
    if (!average.is_empty()) SaveAtomically(average, checkpoint_tmp / "last_average.pt");
    net->to(device);
    if (!average.is_empty()) average->to(device);
    SaveAtomically(optimizer, checkpoint_tmp / "last_optim.pt");
    fs::remove_all(checkpoint);
    fs::rename(checkpoint_tmp, checkpoint);
    nlohmann::json log = nlohmann::json::array();
    for (const EpochRecord& e : result.log) log.push_back(EpochJson(e));
    state = {{"epoch", epoch}, {"model", ToJson(config)}, {"log", log}, {"seed", o.seed},
             {"crop_scales", o.crop_scales}, {"flip", o.flip}, {"aux_tracks", o.aux_tracks},
             {"aux_phase_bins", o.aux_phase_bins}, {"aux_world", o.aux_world}, {"point_maps", o.point_maps},
             {"weight_average", o.weight_average}, {"average_steps", average_steps},
             {"best_val_rmse", result.best_val_rmse}, {"checkpoint", checkpoint_name},
             {"batch", o.batch}, {"weight_decay", o.weight_decay}, {"grad_clip", o.grad_clip},
             {"epochs", o.epochs}, {"lr", o.lr}, {"lr_schedule", o.lr_schedule}, {"lr_decay_epoch", o.lr_decay_epoch},
             {"validated_on", result.validated_on}, {"data_fingerprint", data_fingerprint}};
    WriteFileAtomically(state_path, state.dump(2));
    if (better || raw_better) PublishBestModels(checkpoint, o.out);
    // Older checkpoints (and the files of the layout before checkpoint folders) once state.json
    // names the new one.
    for (const auto& entry : fs::directory_iterator(o.out)) {
      const std::string name = entry.path().filename().string();
      if ((IsCheckpointName(name) && name[0] != '.' && name != checkpoint_name) || name == "last.pt" ||
          name == "last_optim.pt" || name == "last_average.pt")
        fs::remove_all(entry.path());
    }
    WriteFileAtomically(o.out / "log.tsv", LogTsv(result.log));
    // The last epoch's plot is the one reported: an earlier one's failure stayed, naming a .gp.err
    // a later plot had removed.
    result.plot_error.clear();
    if (!PlotLearningCurve(result.log, o.out / "learning_curve.png", &result.plot_error, result.validated_on)) {
      // The plot is a convenience; training goes on without it.
    }
    if (o.epoch_done) o.epoch_done(record);
  }
  // Every epoch's validation RMSE NaN or inf (a diverged run, a corrupt target): model.pt was
  // never written, and the run used to end with exit 0 naming it.
  if (!result.log.empty() && !std::isfinite(result.best_val_rmse))
    throw std::runtime_error("no epoch gave a finite validation RMSE (the last: " +
                             std::to_string(result.log.back().val_rmse) + ", train loss " +
                             std::to_string(result.log.back().train_loss) + "): no " + result.model.string() +
                             " was written; see " + (o.out / "log.tsv").string());
  return result;
}

}  // namespace clothwind::learn
