// `train --resume`: the options a run started with, for those the command line leaves out.
#ifndef CLOTHWIND_TOOLS_RESUME_OPTIONS_H_
#define CLOTHWIND_TOOLS_RESUME_OPTIONS_H_

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "learn/model_config.h"
#include "learn/train.h"
#include "usage_error.h"

namespace clothwind::tools {

// Fills the options of a run to be resumed from its state.json, each one only where `given(flag)`
// says the command line left it out: `train --data D --out RUN --resume` refused the defaults one
// option per try ("resume with the --frames the run started with", then --input-size, --width,
// --batch, --epochs ...), though state.json holds them all. Options given are left as they are,
// for Train's own checks to refuse any that differ from the run's.
// Inputs:
//   state_path  the run's state.json; unreadable or incomplete: nothing is filled (Train says why)
//   given       whether the command line gave a flag ("--frames")
// Outputs:
//   o       (in/out) the training options; its model's fields too
//   frames  (in/out) the model's N_t (the verb's own variable)
// Returns the flags filled, in order, for the log. Throws UsageError naming the flags a run of an
// older build did not record (its schedule, batch, weight decay, gradient clip) unless given.
inline std::vector<std::string> FillFromRunState(const std::filesystem::path& state_path,
                                                 const std::function<bool(const std::string&)>& given,
                                                 learn::TrainOptions* o, int* frames) {
  std::vector<std::string> filled;
  nlohmann::json state;
  learn::ModelConfig ran;
  try {
    std::ifstream in(state_path);
    if (!in) return filled;
    state = nlohmann::json::parse(in);
    ran = learn::ModelConfigFromJson(state.at("model"), state_path.string());
  } catch (const std::exception&) {
    return filled;  // Train reads it again and names what is wrong
  }
  auto fill = [&](const std::string& flag, const std::function<void()>& set) {
    if (given(flag)) return;
    set();
    filled.push_back(flag);
  };
  learn::ModelConfig& m = o->model;
  fill("--model", [&] { m.arch = ran.arch; });
  fill("--frames", [&] { *frames = ran.frames; });
  fill("--input-size", [&] { m.input_size = ran.input_size; });
  fill("--width", [&] { m.width = ran.width; });
  fill("--k", [&] { m.k = ran.k; });
  fill("--include-dc", [&] { m.include_dc = ran.include_dc; });
  fill("--dft-size", [&] { m.dft_size = ran.dft_size; });
  fill("--local-peaks", [&] { m.local_peaks = ran.local_peaks; });
  fill("--dropout", [&] { m.dropout = ran.dropout; });
  fill("--phase-steps", [&] { m.phase_steps = ran.phase_steps; });
  fill("--phase-step-far", [&] { m.phase_step_far = ran.phase_step_far; });
  fill("--mode-shape", [&] { m.mode_shape = ran.mode_shape; });
  fill("--spectral-pool", [&] { m.spectral_pool = ran.spectral_pool; });
  fill("--no-stem-pool", [&] { m.stem_pool = ran.stem_pool; });
  fill("--coord-maps", [&] { m.coord_maps = ran.coord_maps; });
  fill("--flow", [&] { m.flow = ran.flow; });
  fill("--flow-size", [&] { m.flow_size = ran.flow_size; });
  fill("--colour", [&] { m.colour = ran.colour; });
  fill("--head-hidden", [&] { m.head_hidden = ran.head_hidden; });
  fill("--frame-channels", [&] { m.frame_channels = ran.frame_channels; });
  fill("--mean-map", [&] { m.mean_map = ran.mean_map; });
  // (--still-floor: Train takes the run's own when it is not given.)
  // Training options, where the state records them. Runs before 2026-12-05 recorded none of the
  // schedule, batch, weight decay and gradient clip: Train could check only the log's rates against
  // them, which after one epoch cannot tell cosine from step or 20 epochs from 40, so those left out
  // would have run as the defaults: refused, naming the flags to give.
  std::vector<std::string> unrecorded;
  for (const auto& [key, flag] : {std::pair{"epochs", "--epochs"}, std::pair{"batch", "--batch"},
                                  std::pair{"lr", "--lr"}, std::pair{"lr_schedule", "--lr-schedule"},
                                  std::pair{"lr_decay_epoch", "--lr-decay-epoch"},
                                  std::pair{"weight_decay", "--weight-decay"}, std::pair{"grad_clip", "--grad-clip"}})
    if (!state.contains(key) && !given(flag)) unrecorded.push_back(flag);
  if (!unrecorded.empty()) {
    std::string flags;
    for (const std::string& flag : unrecorded) flags += (flags.empty() ? "" : ", ") + flag;
    throw UsageError(state_path.string() + " (a run of an older build) does not record " + flags +
                     ": give them as the run started with");
  }
  auto recorded = [&](const char* key, const std::string& flag, const std::function<void(const nlohmann::json&)>& set) {
    if (!state.contains(key)) return;
    try {
      const nlohmann::json& v = state.at(key);
      if (!given(flag)) {
        set(v);
        filled.push_back(flag);
      }
    } catch (const std::exception&) {
    }
  };
  recorded("epochs", "--epochs", [&](const nlohmann::json& v) { o->epochs = v.get<int>(); });
  recorded("batch", "--batch", [&](const nlohmann::json& v) { o->batch = v.get<int>(); });
  recorded("lr", "--lr", [&](const nlohmann::json& v) { o->lr = v.get<double>(); });
  recorded("lr_schedule", "--lr-schedule", [&](const nlohmann::json& v) { o->lr_schedule = v.get<std::string>(); });
  recorded("lr_decay_epoch", "--lr-decay-epoch", [&](const nlohmann::json& v) { o->lr_decay_epoch = v.get<int>(); });
  recorded("crop_scales", "--crop-scales",
           [&](const nlohmann::json& v) { o->crop_scales = v.get<std::vector<double>>(); });
  recorded("aux_tracks", "--aux-tracks", [&](const nlohmann::json& v) { o->aux_tracks = v.get<double>(); });
  recorded("flip", "--no-flip", [&](const nlohmann::json& v) { o->flip = v.get<bool>(); });
  recorded("aux_phase_bins", "--aux-phases", [&](const nlohmann::json& v) { o->aux_phase_bins = v.get<int>(); });
  recorded("aux_world", "--aux-world", [&](const nlohmann::json& v) { o->aux_world = v.get<bool>(); });
  recorded("point_maps", "--point-maps", [&](const nlohmann::json& v) { o->point_maps = v.get<bool>(); });
  recorded("weight_average", "--weight-average", [&](const nlohmann::json& v) { o->weight_average = v.get<double>(); });
  recorded("weight_decay", "--weight-decay", [&](const nlohmann::json& v) { o->weight_decay = v.get<double>(); });
  recorded("grad_clip", "--grad-clip", [&](const nlohmann::json& v) { o->grad_clip = v.get<double>(); });
  recorded("seed", "--seed", [&](const nlohmann::json& v) { o->seed = v.get<uint64_t>(); });
  return filled;
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_RESUME_OPTIONS_H_
