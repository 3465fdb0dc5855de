#include "learn/model_config.h"

#include "common/atomic_file.h"

#include <cerrno>
#include <cmath>
#include <limits>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

#include "learn/track_targets.h"

namespace clothwind::learn {

int ModelConfig::TrunkInputChannels() const {
  const int coords = coord_maps ? 2 : 0;
  if (arch == "sdn") {
    const int phase = phase_steps ? (phase_step_far > 1 ? 8 : 4) : 0;
    return (2 * k + (mean_map ? 1 : 0) + phase + (mode_shape ? 2 : 0) + frame_channels) * channels + coords;
  }
  return (arch == "lstm" ? channels : frames * channels) + coords;
}

SpectralOptions ModelConfig::Spectral() const {
  SpectralOptions o;
  o.k = k;
  o.frame_rate = frame_rate;
  o.include_dc = include_dc;
  o.dft_size = dft_size;
  o.local_peaks = local_peaks;
  o.phase_steps = phase_steps;
  o.phase_step_far = phase_step_far;
  o.mode_shape = mode_shape;
  o.still_floor = still_floor;
  return o;
}

int ModelConfig::SpectralCandidates() const {
  return DftLength() / 2 + (include_dc ? 1 : 0);
}

bool ModelConfig::PhaseStepFarIsValid() const {
  return phase_step_far == 0 || (phase_step_far >= 2 && phase_steps);
}

std::vector<int64_t> ModelConfig::FrameChannelIndices() const {
  if (frame_channels == 1) return {(frames - 1) / 2};
  std::vector<int64_t> indices;
  for (int i = 0; i < frame_channels; ++i) {
    // i·(T−1)/(N−1) rounded half up, in integers: exact for every N and T.
    indices.push_back((2 * static_cast<int64_t>(i) * (frames - 1) + (frame_channels - 1)) / (2 * (frame_channels - 1)));
  }
  return indices;
}

bool ModelConfig::SpectralPoolIsValid() const {
  return spectral_pool >= 1 && input_size % spectral_pool == 0 && (spectral_pool == 1 || arch == "sdn");
}

SampleOptions ModelConfig::Sampling() const {
  SampleOptions o;
  o.frames = frames;
  o.input_size = input_size;
  o.flow = flow;
  o.flow_size = flow_size;
  o.colour = colour;
  return o;
}

bool ModelConfig::PointMapsAreValid() const {
  return point_maps == 0 || (point_maps > 0 && arch != "lstm" && aux_outputs >= point_maps * kTargetsPerPoint);
}

bool IsKnownArch(const std::string& arch) { return arch == "sdn" || arch == "resnet18" || arch == "lstm"; }

std::string ModelConfig::Name() const {
  std::ostringstream s;
  if (arch == "sdn") {
    s << "sdn-k" << k << (include_dc ? "dc" : "") << (mean_map ? "m" : "");
    if (dft_size != 0) s << "d" << dft_size;
    if (local_peaks) s << "p";
    if (phase_steps) s << "s";
    if (phase_steps && phase_step_far > 1) s << phase_step_far;
    if (mode_shape) s << "o";
    if (still_floor != 0) s << "z";
    if (frame_channels > 0) s << "+f" << frame_channels;
    if (spectral_pool != 1) s << "/" << spectral_pool;
  }
  else s << arch;
  if (flow) s << "-flow";
  if (flow && flow_size != 0) s << flow_size;
  if (colour) s << "-ycc";
  if (!stem_pool) s << "-np";
  if (coord_maps) s << "-xy";
  if (head_hidden > 0) s << "-h" << head_hidden;
  if (point_maps > 0) s << "-pm";
  s << "-w" << width << "-" << input_size << "-" << frames << "f";
  return s.str();
}

std::string ModelConfig::Modality() const {
  std::ostringstream s;
  if (flow || colour) {
    s << frames << "x" << channels << "x" << input_size << "x" << input_size;
  } else {
    s << frames * channels << "x" << input_size << "x" << input_size;
  }
  return s.str();
}

nlohmann::json ToJson(const ModelConfig& c) {
  return {{"format", "clothwind-model"}, {"version", kModelFormatVersion},   {"arch", c.arch},
          {"frames", c.frames},          {"channels", c.channels}, {"flow", c.flow}, {"flow_size", c.flow_size},
          {"colour", c.colour},
          {"k", c.k},                    {"include_dc", c.include_dc},
          {"mean_map", c.mean_map},      {"dft_size", c.dft_size},
          {"local_peaks", c.local_peaks},  {"phase_steps", c.phase_steps},
          {"phase_step_far", c.phase_step_far}, {"mode_shape", c.mode_shape},
          {"still_floor", c.still_floor},
          {"spectral_pool", c.spectral_pool}, {"stem_pool", c.stem_pool},
          {"coord_maps", c.coord_maps}, {"frame_channels", c.frame_channels},
          {"dropout", c.dropout},        {"aux_outputs", c.aux_outputs}, {"point_maps", c.point_maps},
          {"head_hidden", c.head_hidden}, {"flips_in_training", c.flips_in_training},
          {"frame_rate", c.frame_rate},  {"width", c.width},
          {"input_size", c.input_size},  {"label_mean", c.label_mean},
          {"label_std", c.label_std},    {"std_scale", c.std_scale}};
}

namespace {

// The WindNet constructor's checks of how many frames, peaks and frame channels an SDN can have,
// made here where the file is known: a 30-frame model.json with "k": 20 or "frame_channels": 40
// used to pass and then fail in eval, export-model or sdn_node with the constructor's
// std::invalid_argument, naming no file (and train's early check of its options missed them).
// Throws std::runtime_error prefixed with `where`, naming the field and what it may be.
void CheckSpectralShape(const ModelConfig& c, const std::string& where) {
  if (c.arch == "sdn" && c.frames < 2) {
    throw std::runtime_error(where + ": field \"frames\" must be at least 2 on an \"sdn\" (a spectrum needs two "
                             "frames), got " + std::to_string(c.frames));
  }
  if (c.arch == "sdn" && c.k > c.SpectralCandidates()) {
    throw std::runtime_error(where + ": field \"k\" must be at most the " + std::to_string(c.SpectralCandidates()) +
                             " frequency bins a DFT of " + std::to_string(c.DftLength()) + " frames offers" +
                             (c.include_dc ? " with its DC bin" : "") + ", got " + std::to_string(c.k));
  }
  if (!c.FrameChannelsAreValid()) {
    throw std::runtime_error(where + ": field \"frame_channels\" must be 0, or 1 to \"frames\" (" +
                             std::to_string(c.frames) + ") on an \"sdn\", got " + std::to_string(c.frame_channels) +
                             " on \"" + c.arch + "\"");
  }
}

}  // namespace

ModelConfig ModelConfigFromJson(const nlohmann::json& j, const std::string& where) {
  auto need = [&](const char* key) -> const nlohmann::json& {
    if (!j.is_object() || !j.contains(key)) {
      throw std::runtime_error(where + ": missing field \"" + key + "\"");
    }
    return j.at(key);
  };
  // A whole number within int's range: get<int>() read 16.7 as 16 and 4294967326 as 30, and the
  // copy stored in the weights, read the same way, agreed.
  auto as_int = [&](const char* key, const nlohmann::json& v) {
    if (!v.is_number_integer() || v.get<int64_t>() < std::numeric_limits<int>::min() ||
        v.get<int64_t>() > std::numeric_limits<int>::max())
      throw std::runtime_error(where + ": field \"" + key + "\" must be an integer, got " + v.dump());
    return v.get<int>();
  };
  // A model from a newer clothwind: an option this build does not know was ignored, and the
  // network computed other features from the same weights without a word (an older sdn_node
  // loading a model trained with the still floor would have). Every field is one ToJson writes;
  // a new option must come with a higher format version.
  if (j.is_object()) {
    if (j.contains("version") &&
        (!j["version"].is_number_integer() || j["version"].get<int64_t>() < 1 ||
         j["version"].get<int64_t>() > kModelFormatVersion))
      throw std::runtime_error(where + ": field \"version\" is " + j["version"].dump() +
                               ", this clothwind reads model format version " + std::to_string(kModelFormatVersion) +
                               " (a model written by a newer clothwind?)");
    static const nlohmann::json kKnown = ToJson(ModelConfig{});
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (!kKnown.contains(it.key()))
        throw std::runtime_error(where + ": field \"" + it.key() + "\" is not one this clothwind knows (a model " +
                                 "written by a newer clothwind? this one reads model format version " +
                                 std::to_string(kModelFormatVersion) + ")");
    }
  }
  // The kind of every field read with get<> below, checked first: a wrong one threw nlohmann's
  // "type must be boolean, but is string", naming the file but not the field.
  if (j.is_object()) {
    using Is = bool (nlohmann::json::*)() const noexcept;
    static const std::pair<Is, const char*> kBoolean{&nlohmann::json::is_boolean, "true or false"},
        kNumber{&nlohmann::json::is_number, "a number"}, kString{&nlohmann::json::is_string, "a string"};
    static const std::pair<const char*, const std::pair<Is, const char*>*> kFields[] = {
        {"format", &kString},       {"arch", &kString},          {"flow", &kBoolean},
        {"colour", &kBoolean},      {"include_dc", &kBoolean},   {"mean_map", &kBoolean},
        {"local_peaks", &kBoolean}, {"phase_steps", &kBoolean},  {"mode_shape", &kBoolean},
        {"stem_pool", &kBoolean},   {"coord_maps", &kBoolean},   {"flips_in_training", &kBoolean},
        {"dropout", &kNumber},      {"frame_rate", &kNumber},    {"label_mean", &kNumber},
        {"label_std", &kNumber},    {"std_scale", &kNumber},     {"still_floor", &kNumber}};
    for (const auto& [key, kind] : kFields) {
      if (j.contains(key) && !(j[key].*(kind->first))())
        throw std::runtime_error(where + ": field \"" + key + "\" must be " + kind->second + ", got " + j[key].dump());
    }
  }
  ModelConfig c;
  try {
    if (need("format").get<std::string>() != "clothwind-model") {
      throw std::runtime_error(where + ": field \"format\" must be \"clothwind-model\"");
    }
    c.arch = need("arch").get<std::string>();
    c.frames = as_int("frames", need("frames"));
    c.channels = as_int("channels", need("channels"));
    // Absent in models written before flow channels existed: greyscale only.
    c.flow = j.contains("flow") ? j.at("flow").get<bool>() : false;
    c.flow_size = j.contains("flow_size") ? as_int("flow_size", j.at("flow_size")) : 0;
    // Absent in models written before colour input existed: greyscale.
    c.colour = j.contains("colour") ? j.at("colour").get<bool>() : false;
    c.k = as_int("k", need("k"));
    c.include_dc = need("include_dc").get<bool>();
    // Absent in models written before the mean map existed: they had none.
    c.mean_map = j.contains("mean_map") ? j.at("mean_map").get<bool>() : false;
    // Absent in models written before padding and peak picking existed: Algorithm 1's bins.
    c.dft_size = j.contains("dft_size") ? as_int("dft_size", j.at("dft_size")) : 0;
    c.local_peaks = j.contains("local_peaks") ? j.at("local_peaks").get<bool>() : false;
    c.phase_steps = j.contains("phase_steps") ? j.at("phase_steps").get<bool>() : false;
    c.phase_step_far = j.contains("phase_step_far") ? as_int("phase_step_far", j.at("phase_step_far")) : 0;
    c.mode_shape = j.contains("mode_shape") ? j.at("mode_shape").get<bool>() : false;
    // Absent in models written before the option existed: still pixels' frequencies as top-k gave them.
    c.still_floor = j.contains("still_floor") ? j.at("still_floor").get<double>() : 0.0;
    c.spectral_pool = j.contains("spectral_pool") ? as_int("spectral_pool", j.at("spectral_pool")) : 1;
    // Absent in models written before the option existed: they pooled after the stem.
    c.stem_pool = j.contains("stem_pool") ? j.at("stem_pool").get<bool>() : true;
    // Absent in models written before the option existed: no coordinate channels.
    c.coord_maps = j.contains("coord_maps") ? j.at("coord_maps").get<bool>() : false;
    // Absent in models written before the option existed: the spectral maps alone.
    c.frame_channels = j.contains("frame_channels") ? as_int("frame_channels", j.at("frame_channels")) : 0;
    if (c.frame_channels < 0) throw std::runtime_error(where + ": field \"frame_channels\" must be >= 0");
    c.dropout = j.contains("dropout") ? j.at("dropout").get<double>() : 0.0;
    // Absent in models written before auxiliary targets existed: no second head.
    c.aux_outputs = j.contains("aux_outputs") ? as_int("aux_outputs", j.at("aux_outputs")) : 0;
    if (c.aux_outputs < 0) throw std::runtime_error(where + ": field \"aux_outputs\" must be >= 0");
    // Absent in models written before the option existed: the linear head finds the points.
    c.point_maps = j.contains("point_maps") ? as_int("point_maps", j.at("point_maps")) : 0;
    // Absent in models written before the option existed: a linear wind head.
    c.head_hidden = j.contains("head_hidden") ? as_int("head_hidden", j.at("head_hidden")) : 0;
    if (c.head_hidden < 0 || c.head_hidden > 4096)
      throw std::runtime_error(where + ": field \"head_hidden\" must be in 0..4096, got " + std::to_string(c.head_hidden));
    // Absent in models written before train --no-flip existed: they were trained with flips.
    c.flips_in_training = j.contains("flips_in_training") ? j.at("flips_in_training").get<bool>() : true;
    c.frame_rate = need("frame_rate").get<double>();
    c.width = as_int("width", need("width"));
    c.input_size = as_int("input_size", need("input_size"));
    c.label_mean = need("label_mean").get<double>();
    c.label_std = need("label_std").get<double>();
    // Absent in models written before calibration existed: the std as trained.
    c.std_scale = j.contains("std_scale") ? j.at("std_scale").get<double>() : 1.0;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
  if (!IsKnownArch(c.arch)) {
    throw std::runtime_error(where + ": field \"arch\" must be \"sdn\", \"resnet18\" or \"lstm\", got \"" +
                             c.arch + "\"");
  }
  // Each field in its range, named with its value when not. The upper bounds lie far above any
  // model here, so a typo fails here and not as an allocation of terabytes (width 100000 asked
  // for 360 GB).
  auto check = [&where](const char* field, double value, bool ok, const char* expected) {
    if (ok) return;
    std::ostringstream got;
    got << std::setprecision(15) << value;  // counts in full (2147483647, not 2.14748e+09)
    throw std::runtime_error(where + ": field \"" + field + "\" must be " + expected + ", got " + got.str());
  };
  check("frames", c.frames, c.frames >= 1 && c.frames <= 1000, "in 1..1000");
  check("channels", c.channels, c.channels >= 1, ">= 1");
  check("width", c.width, c.width >= 1 && c.width <= 512, "in 1..512");
  check("input_size", c.input_size, c.input_size >= 16 && c.input_size <= 1024, "in 16..1024");
  check("k", c.k, c.k >= 1 && c.k <= 64, "in 1..64");
  check("flow_size", c.flow_size, c.flow_size <= 1024, "<= 1024");
  check("dft_size", c.dft_size, c.dft_size <= 100000, "<= 100000");
  check("aux_outputs", c.aux_outputs, c.aux_outputs <= 100000, "<= 100000");
  check("point_maps", c.point_maps, c.point_maps <= 10000, "<= 10000");
  check("frame_rate", c.frame_rate, c.frame_rate > 0 && c.frame_rate <= 1000, "in (0, 1000] Hz");
  check("label_mean", c.label_mean, std::isfinite(c.label_mean), "finite [m/s]");
  check("label_std", c.label_std, std::isfinite(c.label_std) && c.label_std > 0, "finite and > 0 [m/s]");
  check("std_scale", c.std_scale, std::isfinite(c.std_scale) && c.std_scale > 0, "finite and > 0");
  if (const std::string field = c.SpectralOptionOffSdn(); !field.empty()) {
    throw std::runtime_error(where + ": field \"" + field + "\" is an option of the spectral layer, which \"arch\" \"" +
                             c.arch + "\" does not have");
  }
  if (!c.ColourIsValid()) {
    throw std::runtime_error(where + ": field \"colour\" must be false with \"flow\" (the flow is the grey frames')");
  }
  if (c.channels != c.ChannelsForInput()) {
    throw std::runtime_error(where + ": field \"channels\" must be " + std::to_string(c.ChannelsForInput()) +
                             (c.flow ? " (grey and flow x, y)" : c.colour ? " (Y, Cr, Cb)" : " (grey)") + ", got " + std::to_string(c.channels));
  }
  if (!c.FlowSizeIsValid()) {
    throw std::runtime_error(where + ": field \"flow_size\" must be 0, or at least 16 with \"flow\", got " +
                             std::to_string(c.flow_size));
  }
  if (!(c.dropout >= 0 && c.dropout < 1)) {
    throw std::runtime_error(where + ": field \"dropout\" must be in [0, 1), got " + std::to_string(c.dropout));
  }
  if (!(c.still_floor >= 0 && c.still_floor < 1)) {
    throw std::runtime_error(where + ": field \"still_floor\" must be in [0, 1), got " + std::to_string(c.still_floor));
  }
  if (!c.PhaseStepFarIsValid()) {
    throw std::runtime_error(where + ": field \"phase_step_far\" must be 0, or at least 2 with \"phase_steps\", got " +
                             std::to_string(c.phase_step_far));
  }
  if (!c.PointMapsAreValid()) {
    throw std::runtime_error(where + ": field \"point_maps\" must be 0, or the number of points P > 0 of an "
                             "\"aux_outputs\" of at least 12 P on an sdn or resnet18, got " +
                             std::to_string(c.point_maps));
  }
  if (!c.ModeShapeIsValid()) {
    throw std::runtime_error(where + ": field \"mode_shape\" is for \"arch\" \"sdn\" without \"include_dc\" only, got \"" +
                             c.arch + "\"" + (c.include_dc ? " with \"include_dc\"" : ""));
  }
  if (!c.SpectralPoolIsValid()) {
    throw std::runtime_error(where + ": field \"spectral_pool\" must be >= 1, divide \"input_size\" (" +
                             std::to_string(c.input_size) + ") and be 1 unless \"arch\" is \"sdn\", got " +
                             std::to_string(c.spectral_pool));
  }
  if (c.dft_size != 0 && c.dft_size < c.frames) {
    throw std::runtime_error(where + ": field \"dft_size\" must be 0 or at least \"frames\" (" +
                             std::to_string(c.frames) + "), got " + std::to_string(c.dft_size));
  }
  CheckSpectralShape(c, where);
  return c;
}

std::filesystem::path ConfigPathFor(const std::filesystem::path& weights) {
  std::filesystem::path p = weights;
  return p.replace_extension(".json");
}

void RequireWeightsFile(const std::filesystem::path& weights, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(weights, ec))
    throw std::runtime_error(weights.string() + ": a folder, expected " + what +
                             "'s weights file (a .pt with its .json beside it)");
  // Named before its .json is read: a mistyped --model said only "nope.json: cannot open".
  if (!std::filesystem::exists(weights, ec))
    throw std::runtime_error(weights.string() + ": no such file, expected " + what +
                             "'s weights file (a .pt with its .json beside it)");
}

void WriteFileAtomically(const std::filesystem::path& path, const std::string& text) {
  clothwind::WriteFileAtomically(path.string(), text);
}

}  // namespace clothwind::learn
