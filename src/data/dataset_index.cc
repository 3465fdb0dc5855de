#include "data/dataset_index.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "common/dataset_names.h"
#include "common/json_file.h"
#include "sim/trajectory_io.h"

namespace clothwind::data {

namespace fs = std::filesystem;

nlohmann::json ZetaLabelJson(const render::RenderParams& zeta) {
  // The background photo by its file name (as the settings list them): the folder it was read
  // from differs between machines, and labels are byte-identical on every one.
  render::RenderParams recorded = zeta;
  if (!recorded.background_image.empty())
    recorded.background_image = fs::path(recorded.background_image).filename().string();
  return render::ToJson(recorded);
}

nlohmann::json SimExampleLabel(const std::string& name, const SimulationSample& s,
                               const render::RenderParams& zeta, const ClipInfo& info) {
  nlohmann::json theta = nlohmann::json::array(), names = nlohmann::json::array(),
                 units = nlohmann::json::array();
  for (int i = 0; i < sim::kNumParameters; ++i) {
    theta.push_back(s.theta[i]);
    names.push_back(sim::ParameterNames()[i]);
    units.push_back(sim::ParameterUnits()[i]);
  }
  nlohmann::json j;
  j["format"] = "clothwind-clip";
  j["version"] = kFormatVersion;
  j["name"] = name;
  j["kind"] = "sim";
  j["dataset"] = info.dataset;
  j["num_frames"] = info.num_frames;
  j["frame_rate"] = info.frame_rate;
  j["width"] = zeta.width;
  j["height"] = zeta.height;
  j["encoding"] = info.frame_ext == "pgm" ? "mono8" : "rgb8";
  j["frame_pattern"] = FramePattern(info.frame_ext);
  j["wind_speed"] = s.theta[sim::kWindSpeedIndex];
  j["theta"] = theta;
  j["theta_names"] = names;
  j["theta_units"] = units;
  j["wind_velocity"] = {s.wind_velocity.x(), s.wind_velocity.y(), s.wind_velocity.z()};
  j["zeta"] = ZetaLabelJson(zeta);
  j["seed"] = s.seed;
  j["dataset_seed"] = info.dataset_seed;
  j["simulation"] = s.index;
  j["view"] = info.view;
  j["views"] = info.views;
  j["fabric"] = s.fabric;
  j["split"] = info.split;
  j["generator"] = {{"name", kGeneratorName}, {"version", kGeneratorVersion}};
  j["simulation_settings"] = {{"scene", info.scene},         {"max_edge", info.max_edge},
                              {"vertices", info.vertices},   {"faces", info.faces},
                              {"time_step", info.time_step}, {"warmup", info.warmup},
                              {"frame_time", 1.0 / info.frame_rate}};
  return j;
}

namespace {

void Require(const nlohmann::json& j, const char* field, bool ok, const std::string& path,
             const char* expected) {
  if (!j.contains(field) || !ok)
    throw std::runtime_error(path + ": field '" + field + "' " +
                             (j.contains(field) ? "is " + j[field].dump() + ", expected " + expected
                                                : std::string("is missing")));
}

}  // namespace

nlohmann::json ReadLabel(const std::string& path) {
  nlohmann::json j = ReadJsonFile(path);
  if (!j.is_object()) throw std::runtime_error(path + ": expected a JSON object");
  auto has = [&](const char* f) { return j.contains(f); };
  Require(j, "format", has("format") && j["format"] == "clothwind-clip", path, "\"clothwind-clip\"");
  Require(j, "version", has("version") && j["version"] == kFormatVersion, path, "1");
  Require(j, "name", has("name") && j["name"].is_string(), path, "a string");
  Require(j, "kind", has("kind") && (j["kind"] == "sim" || j["kind"] == "real" || j["kind"] == "toy"), path,
          "\"sim\", \"real\" or \"toy\"");
  // At most the clip message's own bound (100000): 1e12 wrapped in get<int>() to a negative
  // frame number, and the contact sheet asked for "-363689984.jpg".
  Require(j, "num_frames",
          has("num_frames") && j["num_frames"].is_number_integer() && j["num_frames"] > 0 &&
              j["num_frames"] <= 100000,
          path, "a positive integer, at most 100000");
  Require(j, "frame_rate", has("frame_rate") && j["frame_rate"].is_number() && j["frame_rate"] > 0,
          path, "a positive number");
  Require(j, "width", has("width") && j["width"].is_number_integer(), path, "an integer");
  Require(j, "height", has("height") && j["height"].is_number_integer(), path, "an integer");
  Require(j, "encoding", has("encoding") && (j["encoding"] == "rgb8" || j["encoding"] == "mono8"), path,
          "\"rgb8\" or \"mono8\"");
  Require(j, "frame_pattern",
          has("frame_pattern") && j["frame_pattern"].is_string() && ValidFramePattern(j["frame_pattern"]), path,
          "a file pattern with one integer conversion, e.g. \"%03d.jpg\"");
  Require(j, "wind_speed", has("wind_speed") && (j["wind_speed"].is_number() || j["wind_speed"].is_null()),
          path, "a number");
  // Where a label has them (a simulated clip's): indexed as they are, "simulation": 1.5 or "view":
  // 99 of 1 went into the index, and eval then blamed index.json for them.
  auto whole = [&](const char* f) { return j[f].is_number_integer() && j[f] >= 0; };
  if (has("simulation")) Require(j, "simulation", whole("simulation"), path, "a whole number >= 0");
  if (has("views")) Require(j, "views", whole("views") && j["views"] >= 1, path, "a whole number >= 1");
  if (has("view"))
    Require(j, "view", whole("view") && (!has("views") || !j["views"].is_number_integer() || j["view"] < j["views"]),
            path, "a whole number >= 0, below 'views'");
  return j;
}

sim::Theta LabelTheta(const nlohmann::json& label) {
  if (!label.contains("theta") || !label["theta"].is_array() ||
      label["theta"].size() != sim::kNumParameters)
    throw std::runtime_error("label: field 'theta' must be an array of 17 numbers");
  sim::Theta t;
  for (int i = 0; i < sim::kNumParameters; ++i) {
    if (!label["theta"][i].is_number())
      throw std::runtime_error("label: theta[" + std::to_string(i) + "] is not a number");
    t[i] = label["theta"][i].get<double>();
  }
  return t;
}

render::RenderParams LabelZeta(const nlohmann::json& label) {
  if (!label.contains("zeta")) throw std::runtime_error("label: field 'zeta' is missing");
  try {
    return render::RenderParamsFromJson(label["zeta"]);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("label: zeta: ") + e.what());
  }
}

nlohmann::json IndexEntry(const nlohmann::json& label) {
  nlohmann::json e{{"name", label["name"]},
                   {"wind_speed", label["wind_speed"]},
                   {"num_frames", label["num_frames"]}};
  for (const char* f : {"split", "seed", "simulation", "view", "fabric"})
    if (label.contains(f)) e[f] = label[f];
  if (label.contains("theta") && label["theta"].is_array() && !label["theta"].empty())
    e["area_weight"] = label["theta"][sim::kAreaWeightIndex];
  return e;
}

namespace {

// Throws unless `label` (read from `path`) agrees with a make-dataset header's settings block
// `settings` on what both record: kind, seed, views, frames, size, format, rate, generator
// version, scene, warm-up, largest edge, the split its seed falls in, and a wind inside the
// header's range. A field either lacks (an older generator's) is not compared. Why: a merge
// copies other machines' shards into the folder, and a shard run with another --seed, --size,
// --warmup, --wind-max or binary was indexed under this header without a word.
void CheckLabelAgainstSettings(const std::string& path, const nlohmann::json& label, const nlohmann::json& settings) {
  const auto field = [](const nlohmann::json& j, const char* key) {
    return j.is_object() && j.contains(key) ? j[key] : nlohmann::json();
  };
  const auto refuse = [&](const std::string& name, const nlohmann::json& got, const nlohmann::json& header) {
    throw std::runtime_error(path + ": field '" + name + "' is " + got.dump() + ", the dataset's header says " +
                             header.dump() + " (an example made with other settings: remove it, or index it in "
                             "a folder of its own)");
  };
  const nlohmann::json format = field(settings, "frame_format");
  const std::vector<std::tuple<std::string, nlohmann::json, nlohmann::json>> pairs = {
      {"dataset", field(label, "dataset"), field(settings, "kind")},
      {"dataset_seed", field(label, "dataset_seed"), field(settings, "seed")},
      {"views", field(label, "views"), field(settings, "views")},
      {"num_frames", field(label, "num_frames"), field(settings, "frames")},
      {"width", field(label, "width"), field(settings, "size")},
      {"height", field(label, "height"), field(settings, "size")},
      {"frame_pattern", field(label, "frame_pattern"),
       format.is_string() ? nlohmann::json(FramePattern(format.get<std::string>())) : nlohmann::json()},
      {"generator.version", field(field(label, "generator"), "version"), field(settings, "generator_version")},
  };
  for (const auto& [name, got, header] : pairs)
    if (!got.is_null() && !header.is_null() && got != header) refuse(name, got, header);
  const nlohmann::json rate = field(label, "frame_rate"), fps = field(settings, "fps");
  const auto near = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); };
  if (rate.is_number() && fps.is_number() && !near(rate.get<double>(), fps.get<double>())) refuse("frame_rate", rate, fps);
  const nlohmann::json sim = field(label, "simulation_settings");
  const nlohmann::json scene = field(sim, "scene"), header_scene = field(settings, "scene");
  if (!scene.is_null() && !header_scene.is_null() && scene != header_scene)
    refuse("simulation_settings.scene", scene, header_scene);
  const nlohmann::json max_edge = field(sim, "max_edge"), header_edge = field(settings, "max_edge");
  // A header's 0 is "the scene's own" (the label records the edge used).
  if (max_edge.is_number() && header_edge.is_number() && header_edge.get<double>() > 0 &&
      !near(max_edge.get<double>(), header_edge.get<double>()))
    refuse("simulation_settings.max_edge", max_edge, header_edge);
  // The generator rounds the warm-up to whole frames, and the label records it so.
  const nlohmann::json warmup = field(sim, "warmup"), header_warmup = field(settings, "warmup");
  if (warmup.is_number() && header_warmup.is_number() && fps.is_number() && fps.get<double>() > 0) {
    const double frame_time = 1.0 / fps.get<double>();
    const double expected = std::round(header_warmup.get<double>() / frame_time) * frame_time;
    if (!near(warmup.get<double>(), expected)) refuse("simulation_settings.warmup", warmup, expected);
  }
  const nlohmann::json wind = field(label, "wind_speed"), ranges = field(settings, "ranges");
  const nlohmann::json wind_min = field(ranges, "wind_min"), wind_max = field(ranges, "wind_max");
  if (wind.is_number() && wind_min.is_number() && wind_max.is_number() &&
      !(wind.get<double>() >= wind_min.get<double>() - 1e-9 && wind.get<double>() <= wind_max.get<double>() + 1e-9))
    refuse("wind_speed", wind, "within " + wind_min.dump() + ".." + wind_max.dump() + " m/s (ranges.wind_min..wind_max)");
  const nlohmann::json seed = field(label, "seed"), split = field(label, "split");
  const nlohmann::json val = field(settings, "val_fraction"), test = field(settings, "test_fraction");
  if (seed.is_number_unsigned() && split.is_string() && val.is_number() && test.is_number()) {
    const std::string expected = SplitOf(seed.get<uint64_t>(), val.get<double>(), test.get<double>());
    if (split != expected) refuse("split", split, expected + " (its seed's, at val " + val.dump() + ", test " + test.dump() + ")");
  }
}

}  // namespace

std::string FramePattern(const std::string& ext) { return "%03d." + ext; }

bool FrameFileWhole(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size <= 0) return false;
  const std::string ext = file.extension().string();
  auto ends_with = [&](const std::string& tail) {
    if (size < static_cast<std::streamoff>(tail.size())) return false;
    std::string last(tail.size(), '\0');
    in.seekg(size - static_cast<std::streamoff>(tail.size()));
    return static_cast<bool>(in.read(last.data(), static_cast<std::streamsize>(last.size()))) && last == tail;
  };
  if (ext == ".jpg" || ext == ".jpeg") return ends_with("\xFF\xD9");
  if (ext == ".png") return ends_with(std::string("IEND\xAE\x42\x60\x82", 8));
  if (ext == ".pgm") {
    // "P5 <width> <height> <maxval>" and one whitespace byte, then the pixels (2 bytes each past 255).
    in.seekg(0);
    std::string magic;
    int64_t width = 0, height = 0, maxval = 0;
    // (Sides past 2^20 are no frame of ours, and their product could overflow.)
    if (!(in >> magic >> width >> height >> maxval) || magic != "P5" || width <= 0 || height <= 0 ||
        width > (1 << 20) || height > (1 << 20) || maxval <= 0)
      return false;
    const std::streamoff header = static_cast<std::streamoff>(in.tellg()) + 1;
    return size >= header + width * height * (maxval > 255 ? 2 : 1);
  }
  return true;
}

bool FramesPresent(const fs::path& folder, int64_t frames, const std::string& pattern) {
  std::vector<char> name(pattern.size() + 32);
  for (int64_t k = 0; k < frames; ++k) {
    std::snprintf(name.data(), name.size(), pattern.c_str(), static_cast<int>(k));
    if (!FrameFileWhole(folder / name.data())) return false;
  }
  return true;
}

nlohmann::json BuildIndex(const std::string& dir, nlohmann::json header,
                          const std::function<void(int, int)>& progress, std::vector<std::string>* incomplete,
                          std::vector<std::string>* beyond_count, std::vector<std::string>* unlabelled) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name[0] == '.' || !entry.is_directory()) continue;
    std::error_code ec;
    if (fs::exists(entry.path() / "label.json"))
      names.push_back(name);
    else if (unlabelled && !fs::is_empty(entry.path(), ec) && !ec)
      unlabelled->push_back(name);  // not an example, or one still being written (its label comes last)
  }
  std::sort(names.begin(), names.end());
  // (0, n) first, once the folder is listed: a progress bar paces the labels from there.
  if (progress && !names.empty()) progress(0, static_cast<int>(names.size()));
  nlohmann::json clips = nlohmann::json::array();
  for (const auto& name : names) {
    const std::string path = (fs::path(dir) / name / "label.json").string();
    const nlohmann::json label = ReadLabel(path);
    if (header.is_object() && header.contains("dataset")) CheckLabelAgainstSettings(path, label, header["dataset"]);
    if (label["name"] != name)
      throw std::runtime_error(path + ": field 'name' is " + label["name"].dump() +
                               ", expected the folder's name \"" + name + "\"");
    // A simulation beyond the header's count: a larger run's folder (one extending the dataset,
    // stopped before it rewrote the header, or copied in). The header's count is raised to cover
    // it, so it never counts fewer simulations than it lists; refusing it broke `--reindex` of a
    // stopped run, which is what the reindex is for.
    // A generator run (beyond_count given) leaves such folders out instead: it checked only the
    // simulations of its --count against its settings, and a raised count refused its next run.
    // Frames missing (a copy not finished, a frame deleted): not listed, as the generator makes
    // such an example again; a reader of the index would fail on it. (ReadLabel checked both
    // fields: a whole count and a valid pattern.)
    const nlohmann::json simulation = label.value("simulation", nlohmann::json());
    const bool beyond = header.is_object() && header.contains("count") && header["count"].is_number_integer() &&
                        simulation.is_number_integer() && simulation.get<int64_t>() >= header["count"].get<int64_t>();
    if (beyond && beyond_count) {
      beyond_count->push_back(name);
    } else {
      if (beyond) header["count"] = simulation.get<int64_t>() + 1;
      if (FramesPresent(fs::path(dir) / name, label["num_frames"].get<int64_t>(), label["frame_pattern"].get<std::string>()))
        clips.push_back(IndexEntry(label));
      else if (incomplete)
        incomplete->push_back(name);
    }
    if (progress) progress(static_cast<int>(clips.size()), static_cast<int>(names.size()));
  }
  header["clips"] = clips;
  return header;
}

void WriteIndex(const std::string& dir, const nlohmann::json& index) {
  sim::WriteFileAtomically((fs::path(dir) / "index.json").string(), index.dump(1) + "\n");
}

nlohmann::json ReadIndex(const std::string& dir) {
  const std::string path = (fs::path(dir) / "index.json").string();
  if (!fs::exists(path)) return nullptr;
  nlohmann::json j = ReadJsonFile(path);
  // format compared as JSON: value("format", "") of a number threw a bare type error.
  if (!j.is_object() || !j.contains("format") || j["format"] != "clothwind-dataset")
    throw std::runtime_error(path + ": field 'format' must be \"clothwind-dataset\"");
  if (!j.contains("clips") || !j["clips"].is_array())
    throw std::runtime_error(path + ": field 'clips' must be an array");
  // make-dataset's header fields, where present (a recording's or a toy dataset's index has
  // neither): "dataset": "x" made a resume fail on a bare "cannot use key() for non-object
  // iterators", and --reindex wrote it back; a count of "2" was taken without a word.
  if (j.contains("dataset") && !j["dataset"].is_object())
    throw std::runtime_error(path + ": field 'dataset' must be an object (make-dataset's settings), got " +
                             j["dataset"].dump());
  if (j.contains("count") && !(j["count"].is_number_unsigned() || (j["count"].is_number_integer() && j["count"] >= 0)))
    throw std::runtime_error(path + ": field 'count' must be a whole number >= 0 (the simulations), got " +
                             j["count"].dump());
  return j;
}

}  // namespace clothwind::data
