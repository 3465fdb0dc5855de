// Refusing an output inside a dataset's example folders. Why: `eval --json DATA/<clip>/label.json`,
// `train-fly-judge --out DATA/<clip>/003.jpg --overwrite` and `export-model --calibrate-std DATA
// --out DATA/<clip>/label.pt --overwrite` exited 0 having replaced a clip's label or frame (the
// next read of the dataset failed on it); only index.json was guarded.
#ifndef CLOTHWIND_TOOLS_DATASET_OUTPUTS_H_
#define CLOTHWIND_TOOLS_DATASET_OUTPUTS_H_

#include <algorithm>
#include <exception>
#include <filesystem>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "common/dataset_names.h"
#include "common/json_file.h"
#include "output_paths.h"
#include "usage_error.h"

namespace clothwind::tools {

// Throws UsageError naming `option` when `output` (empty: none) is one of the example folders of
// the dataset at `dir` or lies inside one.
// Inputs: index  the dataset's index.json: its clips[].name are the folders (one folder each,
//         ValidClipName); entries of another shape are skipped (the verb's own reading refuses
//         them, naming the field).
// The output's first folder below `dir` is looked up among the names, the paths normalised once:
// normalising both per clip took 10 s for an output inside a 200,000-clip dataset.
inline void RefuseOutputInsideExamples(const std::string& option, const std::filesystem::path& output,
                                       const std::filesystem::path& dir, const nlohmann::json& index) {
  if (output.empty() || dir.empty()) return;
  const std::filesystem::path out = NormalPath(output), in = NormalPath(dir);
  const auto mismatch = std::mismatch(in.begin(), in.end(), out.begin(), out.end());
  if (mismatch.first != in.end() || mismatch.second == out.end()) return;  // not below dir
  const std::string first = mismatch.second->string();
  if (!index.is_object() || !index.contains("clips") || !index["clips"].is_array()) return;
  for (const auto& clip : index["clips"]) {
    if (!clip.is_object() || !clip.contains("name") || !clip["name"].is_string()) continue;
    const std::string& name = clip["name"].get_ref<const std::string&>();
    if (name == first && ValidClipName(name)) {
      const std::filesystem::path folder = std::filesystem::path(dir) / name;
      throw UsageError(option + " " + output.string() + " is " +
                       (std::next(mismatch.second) == out.end() ? "" : "inside ") + "the example folder " +
                       folder.string() + "; write it elsewhere");
    }
  }
}

// As above, reading `dir`/index.json (empty `dir`: no dataset) with the header-only JSON reader
// (so the trainer scripts/device-train builds from learn alone still links); a dataset whose
// index cannot be read is left to the verb's own reading of it, which names what is wrong.
inline void RefuseOutputInsideExamples(const std::string& option, const std::filesystem::path& output,
                                       const std::filesystem::path& dir) {
  if (output.empty() || dir.empty() || !IsAtOrInside(output, dir)) return;
  nlohmann::json index;
  try {
    index = ReadJsonFile((std::filesystem::path(dir) / "index.json").string(), "a dataset's index");
  } catch (const std::exception&) {
    return;
  }
  RefuseOutputInsideExamples(option, output, dir, index);
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_DATASET_OUTPUTS_H_
