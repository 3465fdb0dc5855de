#ifndef CLOTHWIND_DATA_DATASET_GENERATOR_H_
#define CLOTHWIND_DATA_DATASET_GENERATOR_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "data/clip_tracks.h"
#include "data/example_sampling.h"
#include "render/render_params.h"

namespace clothwind::data {

// The most simulations one dataset holds (an example's name holds six digits of its index).
inline constexpr int64_t kMaxSimulations = 1000000;

// `clothwind make-dataset`: FlagSim / ClothSim datasets (docs/datasets.md).
//
// Simulation i (0 <= i < count) draws θ from SimulationSeed(seed, i), is simulated past the
// start-up transient (`warmup`), and its next `frames` frames at `fps` are rendered from `views`
// camera poses; each view is one example folder (ExampleName: "flag-000012-v1") of frames and a
// label.json. Shard k of N does the simulations i ≡ k (mod N), so N machines give exactly the
// files one machine would. A finished example is never redone (its folder exists) or seen half
// written (each folder is written under ".<name>.tmp-<pid>.<boot>.<start>-<n>", ProcessTag, and
// renamed into place).
struct DatasetOptions {
  render::SceneKind kind = render::SceneKind::kFlag;
  int64_t count = 0;           // simulations (examples = count × views), at most kMaxSimulations
  int views = 1;               // camera poses per simulation
  std::string out;             // dataset folder (created)
  uint64_t seed = 1;           // global seed
  int shard = 0, shards = 1;   // this run does simulations i with i % shards == shard
  int jobs = 0;                // parallel simulations (0: all cores)

  std::string scene;           // scene file; "" = DefaultScenePath(kind)
  std::string materials_dir;   // ClothSim fabrics; "" = DefaultMaterialsDir()
  // ClothSim skips these material files (ArcSim ships paper and aluminium, which are no fabric).
  std::vector<std::string> exclude_fabrics{"aluminium", "paper"};
  std::optional<SamplingRanges> ranges;  // unset: DefaultRanges(kind)

  double max_edge = 0.0;       // mesh resolution [m]; 0 = the scene's default (BuildOptions)
  double warmup = 5.0;         // [s] simulated before the first kept frame
  int frames = 60;             // frames per example
  double fps = 25.0;           // must equal 1 / the scene's frame_time
  // Anti-aliasing samples per pixel (0: ζ's default, 4). 2 looks the same at 300x300 after JPEG and
  // renders a 60-frame clip in ~0.6 s on one core instead of ~1 s (docs/datasets.md).
  int samples = 2;
  int size = 300;              // frame width = height [px]
  std::string frame_ext = "jpg";  // "jpg" | "png" | "pgm" (one grey channel)
  int jpeg_quality = 95;
  double val_fraction = 0.1, test_fraction = 0.2;
  std::vector<std::string> background_images;  // empty: procedural backdrops

  bool contact_sheet = true;   // write DIR/contact_sheet.png at the end

  // Each example also gets tracks.json: where this grid of the cloth's material points is in
  // each frame (data/clip_tracks.h), recorded in the settings as "tracks": [cols, rows].
  std::optional<TrackGrid> tracks;
  // With `tracks`: render nothing new, but give every example already in DIR that lacks it its
  // tracks.json, from its simulation run again; a tracks.json without the points' positions
  // ("world", written since 2026-11-28) is made again with them. The run checks each replay against the example's
  // stored last frame (kMaxReplayGreyDifference) so that tracks never describe other frames.
  bool add_tracks = false;
  // Only the simulations of this split ("train", "val" or "test"; "": all), each exactly as the whole
  // dataset would make it (a simulation's split comes from its seed alone). Making: a model is
  // evaluated on a test split without the hours of its training split; a later run without it
  // completes the dataset. With add_tracks: training's auxiliary loss reads the training split's
  // tracks alone, and a replay costs ~40 % of a new example.
  std::string split;
};

// The mean absolute difference [grey levels of 255] allowed between an example's stored last
// frame and the same frame rendered again from its replayed simulation (--add-tracks). Frames
// rendered from one simulation differ only by JPEG's loss: 0.3-0.7 on flagsim-e2's 128-px frames
// at quality 95, where the clip's frame before (the cloth 40 ms earlier) already differs by 3.
constexpr double kMaxReplayGreyDifference = 1.5;

// Progress once before the first simulation (done 0: the work starts) and after each (called
// from worker threads, serialised by the generator).
struct DatasetProgress {
  int64_t done = 0;       // simulations finished (or failed) in this run
  int64_t total = 0;      // simulations this run has to do (not already complete)
  int64_t failed = 0;
  std::string last;       // name of the last example finished
};
using DatasetProgressCallback = std::function<void(const DatasetProgress&)>;

struct DatasetSummary {
  int64_t assigned = 0;          // simulations of this shard
  int64_t skipped = 0;           // already complete (all views present)
  int64_t simulated = 0;         // simulations run now
  int64_t examples_written = 0;  // example folders written now (--add-tracks: tracks.json files)
  int64_t failed = 0;            // simulations that failed (see errors)
  int64_t examples_in_index = 0; // examples in DIR/index.json after this run (all shards)
  int64_t examples_without_tracks = 0;  // --add-tracks: indexed examples still without tracks.json
                                        // (the header then records no "tracks")
  std::vector<std::string> errors;
  double wall_seconds = 0;
  double simulate_seconds = 0;   // summed over workers
  double render_seconds = 0;
  double write_seconds = 0;      // encoding and writing files
  int jobs = 1;
  std::string index_path, contact_sheet_path;
};

// The most parallel simulations (--jobs).
inline constexpr int kMaxJobs = 1024;

// Throws std::invalid_argument naming the option (e.g. "--views must be in 1..64") when `options`
// are out of range; GenerateDataset checks them first too. For the verb, before it says what it
// will make.
void ValidateDatasetOptions(const DatasetOptions& options);

// Generates (or resumes) a dataset. Throws std::invalid_argument on bad options and
// std::runtime_error when DIR holds a dataset made with different settings (naming the field),
// or the scene/materials cannot be loaded. Failures of single simulations do not stop the run:
// they are counted and listed in the summary.
// `index_progress` reports the index's rebuild at the end, (labels read, labels found) as
// BuildIndex's: tens of seconds for 20,000 examples.
DatasetSummary GenerateDataset(const DatasetOptions& options,
                               const DatasetProgressCallback& progress = {},
                               const std::function<void(int, int)>& index_progress = {});

// The settings block ("dataset") stored in index.json: everything that defines the examples'
// content (not shard, jobs or count), so resumed runs and shards can check they agree.
// `scene_files`, `background_files`: the fingerprints of the scene's files and of the background
// photos' ("" leaves one out; GenerateDataset gives them).
nlohmann::json DatasetSettingsJson(const DatasetOptions& options,
                                   const std::vector<std::string>& fabric_names,
                                   const std::string& scene_files = "", const std::string& background_files = "");

// Rebuilds DIR/index.json (and the contact sheet) from the example folders present, keeping the
// existing header: the final merge after shards ran on several machines.
// `progress` is called with (labels read, labels found) as BuildIndex's.
// Returns the number of examples indexed. Throws std::runtime_error when DIR has no index.json or
// it is not a simulated (flag/cloth) dataset: recorded datasets keep the clip writer's index.
int64_t ReindexDataset(const std::string& dir, bool contact_sheet = true,
                       const std::function<void(int, int)>& progress = {});

// Loads the fabrics of a materials folder (every *.json not in `exclude`, sorted by name) with
// the multipliers of the scene's first cloth material.
// Throws std::runtime_error naming the folder when none is found, or a file that is invalid.
std::vector<Fabric> LoadFabrics(const std::string& folder, const std::string& scene_path,
                                const std::vector<std::string>& exclude);

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_DATASET_GENERATOR_H_
