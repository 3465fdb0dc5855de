#ifndef CLOTHWIND_DATA_CONTACT_SHEET_H_
#define CLOTHWIND_DATA_CONTACT_SHEET_H_

#include <functional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace clothwind::data {

struct ContactSheetOptions {
  int max_tiles = 24;  // examples shown at most (evenly spread over the wind speeds)
  int tile = 150;      // tile size [px] (frames are scaled to it)
};

// A grid of a sample of a dataset's examples, for a person to check a dataset at a glance: the
// middle frame of each, labelled with its wind speed and name, ordered by wind speed (so the
// flag lifting with the wind is visible along the rows).
// Inputs:
//   dir    dataset folder
//   index  its index.json (BuildIndex/ReadIndex)
//   progress  called with (0, tiles shown) before the first tile and (tiles read, tiles shown)
//             after each (10,000 frames of a slow disk take minutes)
// Returns CV_8UC3 BGR; empty when the index has no clips. Throws std::runtime_error naming a
// frame that cannot be read.
cv::Mat MakeContactSheet(const std::string& dir, const nlohmann::json& index,
                         const ContactSheetOptions& options = {},
                         const std::function<void(int, int)>& progress = {});

// MakeContactSheet written atomically as a PNG to `path`. Returns false (writing nothing) when
// the index has no clips.
bool WriteContactSheet(const std::string& dir, const nlohmann::json& index, const std::string& path,
                       const ContactSheetOptions& options = {},
                       const std::function<void(int, int)>& progress = {});

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_CONTACT_SHEET_H_
