#ifndef CLOTHWIND_SENSORS_DATASET_WRITER_H_
#define CLOTHWIND_SENSORS_DATASET_WRITER_H_

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sensors/clip_pipeline.h"

namespace clothwind::sensors {

// Where a recorded clip came from (written into its label.json).
struct ClipSourceInfo {
  std::string frame_id;     // camera optical frame
  std::string description;  // e.g. "clip_buffer_node /camera/image_raw"
  nlohmann::json camera;    // optional camera_info summary (K, D, size); null when unknown
  std::string split = "test";  // dataset split (docs/dataset.md); real clips evaluate, as FlagReal
};

// Folder name of a recorded clip: "clip-<UTC yyyymmdd-hhmmss.mmm of its first frame>-<seq>", so
// names sort by time, and replaying the same session twice gives the same names.
std::string ClipFolderName(double first_stamp, uint64_t sequence);

// label.json of a recorded clip (format "clothwind-clip", version 1; see docs/clips.md).
nlohmann::json ClipLabelJson(const LabelledClip& clip, const ClipSourceInfo& source, const std::string& name);

// Records clips as a FlagReal-style dataset: <root>/<name>/000.jpg ... NNN.jpg + label.json, one
// folder per clip, plus <root>/index.json listing every clip. Each clip folder is written under a
// hidden temporary name and renamed into place, and the index is rewritten to a temporary file
// and renamed, so a reader (or a crash) never sees a half-written clip or index. Opening an
// existing dataset appends to its index.
class DatasetWriter {
 public:
  // Inputs:
  //   root          dataset folder (created if missing)
  //   jpeg_quality  1..100 (95)
  // Throws std::runtime_error when the folder cannot be created or its index.json is not valid
  // (the message names the file and what was expected).
  explicit DatasetWriter(const std::string& root, int jpeg_quality = 95);

  // Writes one clip; returns the path of its folder. A folder of the same name is replaced (the
  // same session replayed again). Throws std::runtime_error naming the file that failed.
  std::string Write(const LabelledClip& clip, const ClipSourceInfo& source);

  // Clips listed in the index.
  size_t size() const { return index_["clips"].size(); }
  const std::string& root() const { return root_; }

 private:
  void WriteIndex();

  std::string root_;
  int jpeg_quality_;
  nlohmann::json index_;
};

// Writes `text` to `path` through a temporary file in the same folder and a rename.
// Throws std::runtime_error naming the path when it fails.
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_DATASET_WRITER_H_
