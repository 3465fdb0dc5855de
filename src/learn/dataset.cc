#include "learn/dataset.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <type_traits>
#include <map>
#include <limits>
#include <stdexcept>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "common/dataset_names.h"
#include "common/formatted.h"
#include "common/image_file.h"
#include "common/json_file.h"
#include "common/random.h"
#include "learn/fly_judge.h"
#include "learn/model_config.h"

namespace clothwind::learn {
namespace fs = std::filesystem;
nlohmann::json ReadJson(const fs::path& path) { return ReadJsonFile(path.string()); }

namespace {

// j[key] as T. Throws std::runtime_error naming the file, the field (after `where`, e.g.
// "clips[5].": which of thousands of index entries) and what was expected.
template <typename T>
T Field(const nlohmann::json& j, const char* key, const fs::path& file, const char* expected,
        const std::string& where = "") {
  if (!j.is_object() || !j.contains(key)) {
    throw std::runtime_error(file.string() + ": missing field \"" + where + key + "\" (" + expected + ")");
  }
  if constexpr (std::is_integral_v<T>) {
    // get<int> truncates 30.7 and wraps 4294967326 to 30: an integer in range or an error.
    const nlohmann::json& v = j.at(key);
    if (!v.is_number_integer() || v.get<int64_t>() < std::numeric_limits<T>::min() ||
        v.get<int64_t>() > std::numeric_limits<T>::max())
      throw std::runtime_error(file.string() + ": field \"" + where + key + "\" must be " + expected + ", got " +
                               v.dump());
  }
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw std::runtime_error(file.string() + ": field \"" + where + key + "\" must be " + expected +
                             ", got " + j.at(key).dump());
  }
}

std::string FrameName(const ClipInfo& clip, int index) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), clip.frame_pattern.c_str(), index);
  return buffer;
}

// The split of index.json's clips[i] (`entry`), whose label.json (`label`, at label_path) may
// repeat it: the index's (fixed by seed at generation), else the label's, else "train". Unless
// split_by_clip (a variant re-split in its index alone), the two must agree.
// Throws std::runtime_error naming the file and field for a split other than train, val, test.
std::string ReadClipSplit(const nlohmann::json& entry, const nlohmann::json& label, size_t i,
                          const fs::path& index_path, const fs::path& label_path, bool split_by_clip) {
  const std::string split =
      entry.contains("split")   ? Field<std::string>(entry, "split", index_path, "\"train\", \"val\" or \"test\"",
                                                     "clips[" + std::to_string(i) + "].")
      : label.contains("split") ? Field<std::string>(label, "split", label_path, "\"train\", \"val\" or \"test\"")
                                : std::string("train");
  if (split != "train" && split != "val" && split != "test") {
    throw std::runtime_error(index_path.string() + ": clips[" + std::to_string(i) +
                             "].split must be \"train\", \"val\" or \"test\", got \"" + split + "\"");
  }
  if (!split_by_clip && entry.contains("split") && label.contains("split") && label["split"] != entry["split"]) {
    throw std::runtime_error(index_path.string() + ": clips[" + std::to_string(i) + "].split is " +
                             entry["split"].dump() + " but " + label_path.string() + " says " +
                             label["split"].dump());
  }
  return split;
}

}  // namespace

Dataset ReadDataset(const fs::path& dir) {
  const fs::path index_path = dir / "index.json";
  const nlohmann::json index = ReadJson(index_path);
  if (Field<std::string>(index, "format", index_path, "\"clothwind-dataset\"") != "clothwind-dataset") {
    throw std::runtime_error(index_path.string() + ": field \"format\" must be \"clothwind-dataset\"");
  }
  Dataset dataset;
  dataset.root = dir;
  dataset.kind = Field<std::string>(index, "kind", index_path, "\"flag\", \"cloth\", \"real\" or \"toy\"");
  if (dataset.kind != "flag" && dataset.kind != "cloth" && dataset.kind != "real" && dataset.kind != "toy")
    throw std::runtime_error(index_path.string() + ": field \"kind\" is \"" + dataset.kind +
                             "\", expected \"flag\", \"cloth\", \"real\" or \"toy\"");
  if (!index.contains("clips") || !index["clips"].is_array()) {
    throw std::runtime_error(index_path.string() + ": missing field \"clips\" (an array)");
  }
  // scripts/dataset-variant --split-by-clip re-splits a dataset clip by clip in its index alone
  // (the labels are hard links to the source's): there the index's split is the one, and one
  // simulation in several splits is the point (the leak that variant measures).
  // (Compared as JSON: value() with a string default threw a bare type error, naming no file, on
  // a "variant" of another type.)
  const bool split_by_clip = index.contains("dataset") && index["dataset"].is_object() &&
                             index["dataset"].contains("variant") &&
                             index["dataset"]["variant"] == nlohmann::json("split_by_clip");
  std::map<std::string, size_t> seen;  // name -> its first entry
  std::map<int, std::pair<std::string, std::string>> simulation_split;  // simulation -> (split, a clip's name)
  std::map<int, std::pair<double, std::string>> simulation_wind;        // simulation -> (wind, a clip's name)
  for (size_t i = 0; i < index["clips"].size(); ++i) {
    const nlohmann::json& entry = index["clips"][i];
    ClipInfo clip;
    const std::string where = "clips[" + std::to_string(i) + "].";
    clip.name = Field<std::string>(entry, "name", index_path, "a string", where);
    if (!ValidClipName(clip.name)) {
      throw std::runtime_error(index_path.string() + ": clips[" + std::to_string(i) +
                               "].name must be a folder name, got \"" + clip.name + "\"");
    }
    // A clip listed twice would count twice, or sit in two splits (a test clip trained on).
    if (const auto [it, fresh] = seen.emplace(clip.name, i); !fresh) {
      throw std::runtime_error(index_path.string() + ": clips[" + std::to_string(i) + "].name \"" + clip.name +
                               "\" repeats clips[" + std::to_string(it->second) + "]");
    }
    clip.dir = dir / clip.name;
    if (entry.contains("simulation")) {
      clip.simulation = Field<int>(entry, "simulation", index_path, "a simulation index >= 0", where);
      if (clip.simulation < 0) {
        throw std::runtime_error(index_path.string() + ": clips[" + std::to_string(i) +
                                 "].simulation must be >= 0, got " + std::to_string(clip.simulation));
      }
    }
    const fs::path label_path = clip.dir / "label.json";
    const nlohmann::json label = ReadJson(label_path);
    // The label is the clip's own: a folder copied under another name (or a label copied into
    // it) read another clip's wind without a word. Checked where the label names itself.
    if (label.is_object() && label.contains("name") && label["name"] != clip.name)
      throw std::runtime_error(label_path.string() + ": field \"name\" is " + label["name"].dump() +
                               ", expected the clip's \"" + clip.name + "\" (index.json's clips[" + std::to_string(i) +
                               "]): a label of another clip");
    // Read before an unlabelled clip is left out, so that it is counted in its own split: counted
    // in none, eval --split test reported the train split's unlabelled clips as left out of it.
    clip.split = ReadClipSplit(entry, label, i, index_path, label_path, split_by_clip);
    // A recorded clip the anemometer did not label (no reading in its window): one such clip made
    // train and eval refuse a whole field dataset. Left out and counted; in a simulated or toy
    // dataset every clip has its wind, and a null is an error below.
    if (dataset.kind == "real" && label.contains("wind_speed") && label["wind_speed"].is_null()) {
      ++dataset.unlabelled;
      ++dataset.unlabelled_by_split[clip.split];
      continue;
    }
    clip.wind_speed = Field<double>(label, "wind_speed", label_path, "a number [m/s]");
    clip.num_frames = Field<int>(label, "num_frames", label_path, "a positive integer");
    clip.frame_rate = Field<double>(label, "frame_rate", label_path, "a number [Hz]");
    clip.width = Field<int>(label, "width", label_path, "a positive integer");
    clip.height = Field<int>(label, "height", label_path, "a positive integer");
    clip.frame_pattern = Field<std::string>(label, "frame_pattern", label_path, "a pattern like \"%03d.jpg\"");
    const std::string encoding = Field<std::string>(label, "encoding", label_path, "\"mono8\" or \"rgb8\"");
    if (encoding != "mono8" && encoding != "rgb8") {
      throw std::runtime_error(label_path.string() + ": field \"encoding\" must be \"mono8\" or \"rgb8\", got \"" +
                               encoding + "\"");
    }
    clip.encoding = encoding;
    // Each checked by name with its value. Bounds: a wind no anemometer reads (misread units, a
    // corrupt label) must not be scored; a frame count or size no camera makes must not size a
    // frame cache (num_frames 2e9 asked for 512 GB before reading a frame).
    auto check = [&](bool ok, const char* field, const std::string& got, const char* expected) {
      if (!ok)
        throw std::runtime_error(label_path.string() + ": field \"" + field + "\" must be " + expected + ", got " +
                                 got);
    };
    check(std::isfinite(clip.wind_speed) && clip.wind_speed >= 0 && clip.wind_speed <= 100,
          "wind_speed", FormattedNumber(clip.wind_speed), "a speed in 0..100 m/s");
    // The index repeats each clip's wind (tools sort and pick clips by it); two winds for one clip
    // mean one file was edited or belongs to another dataset, and which one the scores used
    // would be a guess.
    if (entry.contains("wind_speed")) {
      const double listed = Field<double>(entry, "wind_speed", index_path, "a number [m/s]", where);
      if (!(std::abs(listed - clip.wind_speed) <= 1e-6 * std::max(1.0, std::abs(clip.wind_speed)))) {
        throw std::runtime_error(index_path.string() + ": clips[" + std::to_string(i) + "].wind_speed is " +
                                 FormattedNumber(listed) + " m/s but " + label_path.string() + " says " +
                                 FormattedNumber(clip.wind_speed));
      }
    }
    check(clip.num_frames >= 1 && clip.num_frames <= 100000, "num_frames", std::to_string(clip.num_frames),
          "in 1..100000");
    check(std::isfinite(clip.frame_rate) && clip.frame_rate > 0 && clip.frame_rate <= 10000, "frame_rate",
          FormattedNumber(clip.frame_rate), "a rate in (0, 10000] Hz");
    check(clip.width >= 1 && clip.width <= 16384, "width", std::to_string(clip.width), "in 1..16384 px");
    check(clip.height >= 1 && clip.height <= 16384, "height", std::to_string(clip.height), "in 1..16384 px");
    if (!ValidFramePattern(clip.frame_pattern)) {
      throw std::runtime_error(label_path.string() + ": field \"frame_pattern\" must hold one integer "
                               "conversion like \"%03d.jpg\", got \"" + clip.frame_pattern + "\"");
    }
    // The views of one simulation share its flag's motion: in two splits, a test clip's motion is
    // trained on (the leak docs/sdn.md measures). The generator splits by simulation; a merged or
    // re-indexed dataset might not.
    // Its views film one flag in one wind: two winds under one simulation index are a merge or
    // re-index gone wrong, and the per-simulation figures of eval would mean nothing (eval used
    // to find it only after predicting every clip).
    if (clip.simulation >= 0) {
      const auto [it, fresh] = simulation_wind.emplace(clip.simulation, std::make_pair(clip.wind_speed, clip.name));
      if (!fresh && std::abs(it->second.first - clip.wind_speed) > 1e-9) {
        throw std::runtime_error(index_path.string() + ": simulation " + std::to_string(clip.simulation) +
                                 " has clips of two winds (\"" + it->second.second + "\" " +
                                 FormattedNumber(it->second.first) + " m/s, \"" + clip.name + "\" " +
                                 FormattedNumber(clip.wind_speed) + " m/s): its views film one wind");
      }
    }
    if (clip.simulation >= 0 && !split_by_clip) {
      const auto [it, fresh] = simulation_split.emplace(clip.simulation, std::make_pair(clip.split, clip.name));
      if (!fresh && it->second.first != clip.split) {
        throw std::runtime_error(index_path.string() + ": simulation " + std::to_string(clip.simulation) +
                                 " has clips in two splits (\"" + it->second.second + "\" in " + it->second.first +
                                 ", \"" + clip.name + "\" in " + clip.split +
                                 "): its views share one motion, so a split must hold all of them");
      }
    }
    dataset.clips.push_back(std::move(clip));
  }
  return dataset;
}

void CheckClipsSuitModel(const std::vector<ClipInfo>& clips, double model_rate, bool colour, int frames) {
  for (const ClipInfo& c : clips) {
    // Checked before any work: a short clip used to fail when its turn came to be read (after a
    // whole training epoch), naming neither the clip nor its file.
    if (c.num_frames < frames)
      throw std::runtime_error((c.dir / "label.json").string() + ": field \"num_frames\" is " +
                               std::to_string(c.num_frames) + ", the model reads " + std::to_string(frames) +
                               " frames per clip");
    if (colour && c.encoding == "mono8")
      throw std::runtime_error((c.dir / "label.json").string() +
                               ": field \"encoding\" is \"mono8\", the model reads colour (rgb8) clips");
    if (std::abs(c.frame_rate - model_rate) > 0.01 * model_rate)
      throw std::runtime_error((c.dir / "label.json").string() + ": field \"frame_rate\" is " +
                               FormattedNumber(c.frame_rate) + " Hz, the model reads clips at " +
                               FormattedNumber(model_rate) + " Hz");
  }
}

size_t UnlabelledIn(const Dataset& dataset, const std::string& split) {
  if (split == "all") return dataset.unlabelled;
  const auto it = dataset.unlabelled_by_split.find(split);
  return it == dataset.unlabelled_by_split.end() ? 0 : it->second;
}

std::vector<ClipInfo> SelectSplit(const Dataset& dataset, const std::string& split) {
  if (split != "all" && split != "train" && split != "val" && split != "test") {
    throw std::invalid_argument("split must be train, val, test or all, got \"" + split + "\"");
  }
  std::vector<ClipInfo> out;
  for (const ClipInfo& c : dataset.clips) {
    if (split == "all" || c.split == split) out.push_back(c);
  }
  return out;
}

std::vector<cv::Mat> LoadFrames(const ClipInfo& clip, int first, int count, bool colour) {
  if (first < 0 || count < 1 || first + count > clip.num_frames) {
    throw std::runtime_error((clip.dir / "label.json").string() + ": frames " + std::to_string(first) + ".." +
                             std::to_string(first + count - 1) + " requested but num_frames is " +
                             std::to_string(clip.num_frames));
  }
  std::vector<cv::Mat> frames;
  frames.reserve(count);
  for (int i = first; i < first + count; ++i) {
    const fs::path path = clip.dir / FrameName(clip, i);
    if (!fs::exists(path)) throw std::runtime_error(path.string() + ": missing frame");
    // Whole or refused: a JPEG cut short decodes with made-up grey rows (common/image_file.h).
    std::string why;
    cv::Mat image = common::ReadImageFile(path, colour ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE, &why);
    if (image.empty()) throw std::runtime_error(path.string() + ": " + why);
    if (colour) cv::cvtColor(image, image, cv::COLOR_BGR2YCrCb);
    if (image.cols != clip.width || image.rows != clip.height) {
      throw std::runtime_error(path.string() + ": image is " + std::to_string(image.cols) + "x" +
                               std::to_string(image.rows) + " but label.json says " + std::to_string(clip.width) +
                               "x" + std::to_string(clip.height));
    }
    frames.push_back(image);
  }
  return frames;
}

std::vector<cv::Mat> CameraFramesForModel(const std::vector<cv::Mat>& frames, bool colour) {
  std::vector<cv::Mat> out;
  out.reserve(frames.size());
  for (const cv::Mat& f : frames) {
    if (f.type() == CV_8UC1 && !colour) {
      out.push_back(f);
    } else if (f.type() == CV_8UC3) {
      cv::Mat converted;
      cv::cvtColor(f, converted, colour ? cv::COLOR_BGR2YCrCb : cv::COLOR_BGR2GRAY);
      out.push_back(converted);
    } else if (f.type() == CV_8UC1) {
      throw std::invalid_argument(
          "the model reads colour (Y, Cr, Cb) but the clip is grey (mono8); set the clip buffer's ~colour "
          "parameter to true so clips come as bgr8");
    } else {
      throw std::invalid_argument("clip frames must be 8-bit grey (mono8) or BGR (bgr8) images");
    }
  }
  return out;
}

int ChooseFirstFrame(int num_frames, const SampleOptions& options, std::mt19937_64& rng) {
  if (num_frames < options.frames) {
    throw std::runtime_error("clip has " + std::to_string(num_frames) + " frames, the model needs " +
                             std::to_string(options.frames));
  }
  const int slack = num_frames - options.frames;
  if (options.first_frame >= 0) {
    if (options.first_frame > slack) {
      throw std::runtime_error("window start " + std::to_string(options.first_frame) + " + " +
                               std::to_string(options.frames) + " frames runs past the clip's " +
                               std::to_string(num_frames));
    }
    return options.first_frame;
  }
  if (!options.augment) return slack / 2;
  return std::uniform_int_distribution<int>(0, slack)(rng);
}

std::vector<int> EvenWindowStarts(int num_frames, int frames, int windows) {
  if (windows < 1) throw std::invalid_argument("EvenWindowStarts: windows must be >= 1, got " + std::to_string(windows));
  if (frames < 1 || num_frames < frames) {
    throw std::invalid_argument("EvenWindowStarts: a clip of " + std::to_string(num_frames) + " frames has no window of " +
                                std::to_string(frames));
  }
  const int slack = num_frames - frames;
  if (windows == 1) return {slack / 2};
  // No more windows than there are starts: spaced under a frame apart, rounding repeated starts
  // ({0, 1, 1} for 3 windows of 30 in 31 frames) and eval weighted the repeated window double.
  // Spaced a frame or more apart, the rounded starts are distinct and as before.
  const int count = std::min(windows, slack + 1);
  if (count == 1) return {0};
  std::vector<int> starts;
  for (int j = 0; j < count; ++j) {
    starts.push_back(static_cast<int>(std::lround(static_cast<double>(j) * slack / (count - 1))));
  }
  return starts;
}

cv::Mat FrameFlow(const cv::Mat& previous, const cv::Mat& next) {
  if (previous.type() != CV_8UC1 || next.type() != CV_8UC1 || previous.size() != next.size() || previous.empty()) {
    throw std::invalid_argument("FrameFlow: two non-empty mono8 images of one size expected");
  }
  // One instance per thread: DIS keeps scratch buffers between calls and is not thread-safe.
  thread_local cv::Ptr<cv::DISOpticalFlow> dis = cv::DISOpticalFlow::create(cv::DISOpticalFlow::PRESET_MEDIUM);
  cv::Mat flow;
  dis->calc(previous, next, flow);
  return flow;
}

std::vector<cv::Mat> WindowFlows(const std::vector<cv::Mat>& frames, const cv::Rect& crop, int flow_side, int side) {
  if (flow_side < 1 || side < 1) throw std::invalid_argument("WindowFlows: sides must be >= 1");
  std::vector<cv::Mat> flows(frames.empty() ? 0 : frames.size() - 1);
  cv::Mat previous, next;
  for (size_t t = 0; t < frames.size(); ++t) {
    ResizeCrop(frames[t], crop, flow_side, next);
    if (t > 0) {
      cv::Mat flow = FrameFlow(previous, next);
      if (flow_side != side) {
        cv::Mat resized;
        cv::resize(flow, resized, cv::Size(side, side), 0, 0, flow_side > side ? cv::INTER_AREA : cv::INTER_LINEAR);
        flow = resized * (static_cast<double>(side) / flow_side);
      }
      cv::Mat steps;
      flow.convertTo(steps, CV_16SC2, kFlowSteps);
      steps.convertTo(flows[t - 1], CV_32FC2, 1.0 / kFlowSteps);
    }
    std::swap(previous, next);
  }
  return flows;
}

std::vector<cv::Mat> WindowFlows(const std::vector<cv::Mat>& frames) {
  if (frames.empty()) return {};
  const int side = frames[0].cols;
  return WindowFlows(frames, cv::Rect(0, 0, side, frames[0].rows), side, side);
}

namespace {

// Whether options.flag_flies turns the clip (its first options.frames frames, cropped to `crop`)
// round, so that its flag flies right; `score` receives the judge's (or EstimateFlyDirection's)
// score with kAuto, `undecided` whether the judge could not tell (options.undecided_turns then).
// The frames are judged as the model will see them: cropped, resized (the judge: straight to its
// map side, as it was trained), mirrored by mirror_clip, grey (the Y of colour frames). With kAuto `resized` receives the cropped, resized frames (not
// mirrored), which MakeSample then uses rather than resize them twice (at 300 px the resizing
// costs more than the judging). Frames MakeSample would refuse are not judged (false, `resized`
// left empty): its own checks then name them.
bool TurnsToFlyRight(const std::vector<cv::Mat>& frames, const cv::Rect& crop, const SampleOptions& options,
                     double* score, bool* undecided, std::vector<cv::Mat>* resized) {
  *score = 0;
  *undecided = false;
  resized->clear();
  if (options.flag_flies == FlagFlies::kRight) return false;
  if (options.flag_flies == FlagFlies::kLeft) return true;
  if (options.frames < 4) return false;  // too short to judge (EstimateFlyDirection's minimum)
  const int type = FrameType(options.colour);
  for (int t = 0; t < options.frames; ++t) {
    if (frames[t].type() != type || frames[t].size() != frames[0].size()) return false;
  }
  std::vector<cv::Mat> grey(options.frames);
  resized->resize(options.frames);
  for (int t = 0; t < options.frames; ++t) {
    ResizeCrop(frames[t], crop, options.input_size, (*resized)[t]);
    // The judge reads the crop resized straight to its map side, as it was trained
    // (CollectMotionMaps), not the model's input resized again (96 px, rounded to 8 bits, then to
    // 64: not the inputs its figures were measured on); the motion cues read the model's input.
    cv::Mat g;
    if (options.fly_judge) ResizeCrop(frames[t], crop, kMotionMapSide, g);
    else g = (*resized)[t];
    // The grey (or Y) plane, mirrored into new data: `resized` must stay as it was cropped.
    if (g.channels() > 1) cv::extractChannel(g, g, 0);
    if (options.mirror_clip) cv::flip(g, grey[t], 1);
    else grey[t] = g;
  }
  if (options.fly_judge) {
    const std::optional<FlyDirection> way = options.fly_judge->Judge(grey, score);
    *undecided = !way;
    return way ? *way == FlyDirection::kLeft : options.undecided_turns;
  }
  const FlyDirectionCues cues = EstimateFlyDirection(grey);
  *score = cues.score;
  return cues.direction == FlyDirection::kLeft;
}

}  // namespace

Sample MakeSample(const std::vector<cv::Mat>& frames, const SampleOptions& options, std::mt19937_64& rng,
                  const std::vector<cv::Mat>* flows) {
  if (static_cast<int>(frames.size()) != options.frames || frames.empty()) {
    throw std::invalid_argument("MakeSample: " + std::to_string(frames.size()) + " frames given, " +
                                std::to_string(options.frames) + " expected");
  }
  if (options.flow && options.frames < 2) throw std::invalid_argument("MakeSample: flow needs at least 2 frames");
  if (options.flow && options.colour) {
    throw std::invalid_argument("MakeSample: flow and colour are exclusive (the flow is the grey frames')");
  }
  const int w = frames[0].cols, h = frames[0].rows;
  const int side = std::min(w, h);
  Sample sample;
  std::vector<cv::Mat> judged;  // the resized frames flag_flies auto judged (empty otherwise)
  if (options.augment) {
    const double scale = options.crop_scales.empty()
                             ? 1.0
                             : options.crop_scales[std::uniform_int_distribution<size_t>(
                                   0, options.crop_scales.size() - 1)(rng)];
    const int crop = std::clamp(static_cast<int>(std::lround(side * scale)), 1, side);
    const int x = std::uniform_int_distribution<int>(0, w - crop)(rng);
    const int y = std::uniform_int_distribution<int>(0, h - crop)(rng);
    sample.crop = cv::Rect(x, y, crop, crop);
    sample.flipped = std::uniform_int_distribution<int>(0, 1)(rng) == 1 && options.flip;
  } else {
    sample.crop = CentreSquare(w, h);
    sample.turned = TurnsToFlyRight(frames, sample.crop, options, &sample.fly_score, &sample.undecided, &judged);
    sample.flipped = (options.mirror_clip != sample.turned) != options.mirror;
  }
  const int s = options.input_size;
  const size_t plane = static_cast<size_t>(s) * s;
  const size_t grey = static_cast<size_t>(options.frames) * plane;
  sample.channels = options.channels();
  sample.pixels.resize(grey * sample.channels);
  // The frames' own channels (grey, or Y Cr Cb), each normalised below; flow channels follow.
  const int type = FrameType(options.colour);
  const int own = CV_MAT_CN(type);
  std::vector<double> sum(own, 0.0), sum2(own, 0.0);
  cv::Mat resized;
  std::vector<cv::Mat> split(own);
  for (int t = 0; t < options.frames; ++t) {
    const cv::Mat& f = frames[t];
    if (f.type() != type || f.cols != w || f.rows != h) {
      throw std::invalid_argument("MakeSample: frame " + std::to_string(t) + " is not " + std::to_string(w) + "x" +
                                  std::to_string(h) + (options.colour ? " 8-bit YCrCb" : " mono8"));
    }
    if (judged.empty()) {
      ResizeCrop(f, sample.crop, s, resized);
    } else {
      resized = judged[t];
    }
    if (sample.flipped) cv::flip(resized, resized, 1);
    if (own == 1) split[0] = resized;
    else cv::split(resized, split);
    for (int c = 0; c < own; ++c) {
      cv::Mat out(s, s, CV_32F, sample.pixels.data() + grey * c + static_cast<size_t>(t) * plane);
      split[c].convertTo(out, CV_32F);
      sum[c] += cv::sum(out)[0];
      sum2[c] += out.dot(out);
    }
  }
  // One scale for all of the frames' channels: their deviations' joint std.
  const double n = static_cast<double>(grey);
  double variance = 0;
  for (int c = 0; c < own; ++c) variance += std::max(sum2[c] / n - (sum[c] / n) * (sum[c] / n), 0.0);
  const float inv = static_cast<float>(1.0 / std::max(std::sqrt(variance / own), 1e-3));
  for (int c = 0; c < own; ++c) {
    const float mean = static_cast<float>(sum[c] / n);
    float* p = sample.pixels.data() + grey * c;
    for (size_t i = 0; i < grey; ++i) p[i] = (p[i] - mean) * inv;
  }
  if (options.flow) {
    std::vector<cv::Mat> computed;
    if (flows == nullptr) {
      // Flow of the frames as the network sees them, before the flip (which then mirrors it).
      computed = WindowFlows(frames, sample.crop, options.flow_size > 0 ? options.flow_size : s, s);
      flows = &computed;
    } else if (static_cast<int>(flows->size()) != options.frames - 1 || w != s || h != s) {
      throw std::invalid_argument("MakeSample: " + std::to_string(flows->size()) + " flows of " +
                                  std::to_string(options.frames - 1) + " expected, on frames of the input size");
    }
    for (int t = 0; t < options.frames; ++t) {
      const cv::Mat& f = (*flows)[static_cast<size_t>(std::max(t - 1, 0))];
      if (f.type() != CV_32FC2 || f.rows != s || f.cols != s) {
        throw std::invalid_argument("MakeSample: flow " + std::to_string(t) + " is not " + std::to_string(s) +
                                    "x" + std::to_string(s) + " CV_32FC2");
      }
      cv::Mat xy[2];
      cv::split(f, xy);
      if (sample.flipped) {
        cv::flip(xy[0], xy[0], 1);
        cv::flip(xy[1], xy[1], 1);
        xy[0] = -xy[0];  // mirrored, a motion to the right is one to the left
      }
      for (int c = 0; c < 2; ++c) {
        cv::Mat out(s, s, CV_32F, sample.pixels.data() + grey * (1 + c) + static_cast<size_t>(t) * plane);
        xy[c].copyTo(out);
      }
    }
  }
  return sample;
}

cv::Rect CentreSquare(int width, int height) {
  const int side = std::min(width, height);
  return cv::Rect((width - side) / 2, (height - side) / 2, side, side);
}

void ResizeCrop(const cv::Mat& frame, const cv::Rect& crop, int side, cv::Mat& out) {
  cv::resize(frame(crop), out, cv::Size(side, side), 0, 0, crop.width >= side ? cv::INTER_AREA : cv::INTER_LINEAR);
}

Sample LoadSample(const ClipInfo& clip, const SampleOptions& options, uint64_t seed, const FrameReader& read,
                  const FlowReader& read_flows) {
  std::mt19937_64 rng(seed);
  const int first = ChooseFirstFrame(clip.num_frames, options, rng);
  std::vector<cv::Mat> flows;
  if (options.flow && read_flows) flows = read_flows(first, options.frames);
  Sample sample = MakeSample(read(first, options.frames), options, rng, flows.empty() ? nullptr : &flows);
  sample.first_frame = first;
  sample.wind_speed = static_cast<float>(clip.wind_speed);
  return sample;
}

Sample LoadSample(const ClipInfo& clip, const SampleOptions& options, uint64_t seed) {
  return LoadSample(clip, options, seed,
                    [&clip, &options](int first, int count) { return LoadFrames(clip, first, count, options.colour); });
}

std::vector<double> WriteToyDataset(const fs::path& dir, const ToyDatasetOptions& o,
                                    const std::function<void(int, int)>& progress) {
  fs::create_directories(dir);
  // Only a toy dataset is written over: the index of a FlagSim or recorded dataset (its settings
  // in the header) was removed and replaced by a toy one, for good.
  if (fs::exists(dir / "index.json")) {
    std::ifstream in(dir / "index.json");
    const nlohmann::json index = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    const bool toy = index.is_object() && index.contains("kind") && index["kind"] == "toy";
    if (!toy)
      throw std::runtime_error((dir / "index.json").string() + " is not a toy dataset's index (\"kind\": " +
                               (index.is_object() && index.contains("kind") ? index["kind"].dump() : std::string("none")) +
                               "); write the toy dataset into another folder");
  }
  // The old index goes first and the new one comes last: a run stopped over an earlier dataset
  // left the old index over a mix of both runs' examples, which readers took as whole. Examples
  // of a larger earlier run are removed too.
  fs::remove(dir / "index.json");
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string file = e.path().filename().string();
    int number = -1;
    char rest = 0;
    if (std::sscanf(file.c_str(), "toy-%d%c", &number, &rest) == 1 && number >= o.clips) fs::remove_all(e.path());
    // A stopped run's example being written (".toy-00089.tmp"): only the next run writing that
    // number removed it, and a run of fewer clips left it for good.
    char tail[8] = {0};
    if (std::sscanf(file.c_str(), ".toy-%d.%4s%c", &number, tail, &rest) == 2 && std::string(tail) == "tmp")
      fs::remove_all(e.path());
  }
  nlohmann::json clips = nlohmann::json::array();
  std::vector<double> frequencies;
  if (progress) progress(0, o.clips);
  for (int i = 0; i < o.clips; ++i) {
    const uint64_t seed = o.seed * 1000003ULL + static_cast<uint64_t>(i);
    // common::Rng, not <random>'s distributions (implementation-defined): the toy dataset, and the
    // tests that train on it, are the same with every standard library.
    Rng clip_rng(seed);
    const double speed = clip_rng.Uniform(0, o.max_speed);
    const double f = o.base_frequency + o.frequency_per_speed * speed;
    frequencies.push_back(f);
    const double phase = clip_rng.Uniform(0, 2 * M_PI);
    const int patch = 3 * o.size / 4;
    const int x0 = 1 + clip_rng.UniformInt(o.size - patch - 1);
    const int y0 = 1 + clip_rng.UniformInt(o.size - patch - 1);
    const double wavelength = patch / 3.0;  // [px] three stripes across the patch
    const uint64_t hash = (seed * 0x9E3779B97F4A7C15ULL) >> 33;
    const std::string split = hash % 5 < 3 ? "train" : (hash % 5 == 3 ? "val" : "test");
    char name[32];
    std::snprintf(name, sizeof(name), "toy-%05d", i);
    const fs::path tmp = dir / (std::string(".") + name + ".tmp");
    fs::remove_all(tmp);
    fs::create_directories(tmp);
    // A failure part way (a full disk) removes its temporary folder (it was left behind). The
    // frames are not fsync'ed, unlike make-dataset's: a toy dataset is smoke-test data, made again
    // in seconds, and thousands of fsyncs would slow every test that makes one.
    try {
      for (int t = 0; t < o.frames; ++t) {
        cv::Mat frame(o.size, o.size, CV_8UC1);
        for (int y = 0; y < o.size; ++y) {
          for (int x = 0; x < o.size; ++x) {
            double v = 80 + 10 * std::sin(0.3 * x + 0.2 * y);
            if (x >= x0 && x < x0 + patch && y >= y0 && y < y0 + patch) {
              v = 140 + 60 * std::sin(2 * M_PI * (f * t / o.frame_rate - (x - x0) / wavelength) + phase);
            }
            frame.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(v + 3.0 * clip_rng.Normal());
          }
        }
        char file[32];
        std::snprintf(file, sizeof(file), "%03d.jpg", t);
        if (!cv::imwrite((tmp / file).string(), frame, {cv::IMWRITE_JPEG_QUALITY, 95})) {
          throw std::runtime_error((tmp / file).string() + ": cannot write");
        }
      }
      nlohmann::json label = {{"format", "clothwind-clip"}, {"version", 1},       {"name", name},
                              {"kind", "toy"},              {"num_frames", o.frames},
                              {"frame_rate", o.frame_rate}, {"width", o.size},   {"height", o.size},
                              {"encoding", "mono8"},        {"frame_pattern", "%03d.jpg"},
                              {"wind_speed", speed},        {"seed", seed},      {"split", split},
                              {"generator", {{"name", "learn::WriteToyDataset"}, {"version", 1}}},
                              {"toy_frequency", f}};
      WriteFileAtomically(tmp / "label.json", label.dump(2));
      fs::remove_all(dir / name);
      fs::rename(tmp, dir / name);
    } catch (...) {
      std::error_code ec;
      fs::remove_all(tmp, ec);
      throw;
    }
    clips.push_back({{"name", name}, {"wind_speed", speed}, {"split", split}});
    if (progress) progress(i + 1, o.clips);
  }
  nlohmann::json index = {{"format", "clothwind-dataset"}, {"version", 1}, {"kind", "toy"}, {"clips", clips}};
  WriteFileAtomically(dir / "index.json", index.dump(2));
  return frequencies;
}

}  // namespace clothwind::learn
