#ifndef CLOTHWIND_DATA_DATASET_INDEX_H_
#define CLOTHWIND_DATA_DATASET_INDEX_H_

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "data/example_sampling.h"
#include "render/render_params.h"

namespace clothwind::data {

// label.json and index.json of simulated datasets (docs/dataset.md): format "clothwind-clip" /
// "clothwind-dataset", version 1.
constexpr char kGeneratorName[] = "clothwind make-dataset";
// Bumped when the frames a dataset's settings make change, so a resume does not mix two kinds
// (the settings record it): 2 since 2026-12-06, the cloth's shadow rays leaving from the sunny side
// of their triangle (renderer.cc, ShadeCloth; version 1 darkened single triangles at a grazing sun).
constexpr int kGeneratorVersion = 2;
constexpr int kFormatVersion = 1;

// How an example's frames were made, for its label.
struct ClipInfo {
  std::string dataset;         // "flag" | "cloth"
  uint64_t dataset_seed = 0;   // the global seed
  int view = 0, views = 1;
  std::string split;           // "train" | "val" | "test"
  int num_frames = 60;
  double frame_rate = 25.0;    // [Hz]
  std::string frame_ext = "jpg";  // "jpg" | "png" | "pgm" (one grey channel)
  std::string scene;           // scene file name (no folders: labels must not depend on the machine)
  double max_edge = 0.0;       // mesh resolution [m]
  int vertices = 0, faces = 0;
  double time_step = 0.005;    // [s]
  double warmup = 0.0;         // simulated before frame 0 [s]
};

// The label's "zeta": render::ToJson of `zeta` with its background photo named by file name
// alone (the folder differs between machines; labels are byte-identical on every one).
nlohmann::json ZetaLabelJson(const render::RenderParams& zeta);

// label.json of a simulated example (every field docs/dataset.md lists: name, kind "sim",
// num_frames, frame_rate, width, height, encoding "rgb8", frame_pattern, wind_speed = θ_e,
// theta + theta_names + theta_units, wind_velocity, zeta, seed, generator, split; plus dataset,
// dataset_seed, simulation, view, views, fabric and simulation settings).
nlohmann::json SimExampleLabel(const std::string& name, const SimulationSample& s,
                               const render::RenderParams& zeta, const ClipInfo& info);

// Reads a label.json and checks its format, version and the fields every reader needs
// (name, kind, num_frames, frame_rate, width, height, encoding, frame_pattern, wind_speed).
// Throws std::runtime_error naming the file and the missing/wrong field.
nlohmann::json ReadLabel(const std::string& path);

// Reads theta (17 values) and zeta back from a simulated example's label.
// Throws std::runtime_error naming the field when missing or malformed.
sim::Theta LabelTheta(const nlohmann::json& label);
render::RenderParams LabelZeta(const nlohmann::json& label);

// The index entry of a label: name, wind_speed, split, and for simulated examples seed,
// simulation, view, area_weight, fabric.
nlohmann::json IndexEntry(const nlohmann::json& label);

// The frame file pattern of a generated example whose frames are .<ext> files: "%03d.<ext>",
// label.json's frame_pattern.
std::string FramePattern(const std::string& ext);

// Whether an example folder holds all its frames, whole: an interrupted copy (cp goes in the
// folder's hashed order, so label.json can come before 047.jpg) leaves a label beside missing
// frames, and the frame it was copying cut short (or empty).
// Inputs:
//   folder   the example's folder
//   frames   how many (0 .. frames-1)
//   pattern  the frame file pattern, label.json's frame_pattern (a valid one: ValidFramePattern)
// Returns false at the first frame file that is not there or not whole (FrameFileWhole).
bool FramesPresent(const std::filesystem::path& folder, int64_t frames, const std::string& pattern);

// Whether an image file ends as a whole one does, judged by its ending, not by decoding it (a
// resume reads every frame of every example): a JPEG's end-of-image marker (FF D9), a PNG's IEND
// chunk, a binary PGM's size from its header; another extension: not empty.
// Inputs: file  the image's path. Returns false for a file that is missing, empty or cut short.
bool FrameFileWhole(const std::filesystem::path& file);

// Rebuilds index.json of `dir` from the example folders present (every non-hidden subfolder
// with a label.json), sorted by name, so that any set of runs (shards, resumed runs) that left
// the same folders gives the same index. `header` supplies the top-level fields (format,
// version, kind, generator, dataset settings, count); "clips" is filled in. A label that
// contradicts the header's settings (kind, seed, views, frames, size, format, rate, generator
// version, scene, warm-up, largest edge, the split of its seed, a wind outside the range) is
// refused naming it and the field: a shard made elsewhere with other settings. A simulation
// beyond the header's count raises the count to cover it (a larger run's folder, stopped before
// it rewrote the header), or, when beyond_count is given (a generator run), is left out and
// named there. An example whose frames are not all there is left out.
// `progress`, when set, is called with (0, labels found) once the folder is listed and with
// (labels read, labels found) after each label (a dataset of 20,000 examples takes tens of
// seconds).
// Outputs:
//   incomplete  (optional) the names of the examples left out for missing frames
//   unlabelled  (optional) the names of the non-empty folders without a label.json: not examples,
//               or examples still being written (a label is written last)
// Throws std::runtime_error naming a label.json that cannot be read.
nlohmann::json BuildIndex(const std::string& dir, nlohmann::json header,
                          const std::function<void(int, int)>& progress = {},
                          std::vector<std::string>* incomplete = nullptr,
                          std::vector<std::string>* beyond_count = nullptr,
                          std::vector<std::string>* unlabelled = nullptr);

// Writes index.json atomically (temporary file + rename).
void WriteIndex(const std::string& dir, const nlohmann::json& index);

// Reads DIR/index.json; returns null when absent. Throws std::runtime_error naming the file
// when it is not a clothwind-dataset index.
nlohmann::json ReadIndex(const std::string& dir);

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_DATASET_INDEX_H_
