// Refusing an output inside a dataset's example folders. Why: `eval --json DATA/<clip>/label.json`,
// `train-fly-judge --out DATA/<clip>/003.jpg --overwrite` and `export-model --calibrate-std DATA
// --out DATA/<clip>/label.pt --overwrite` exited 0 having replaced a clip's label or frame (the
// next read of the dataset failed on it); only index.json was guarded.
#ifndef CLOTHWIND_TOOLS_DATASET_OUTPUTS_H_
#define CLOTHWIND_TOOLS_DATASET_OUTPUTS_H_

#include <exception>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "data/dataset_index.h"
#include "output_paths.h"

namespace clothwind::tools {

// Throws UsageError naming `option` when `output` (empty: none) is one of the example folders of
// the dataset at `dir` or lies inside one.
// Inputs: index  the dataset's index.json (data::ReadIndex): its clips[].name are the folders;
//         entries of another shape are skipped (the verb's own reading refuses them, naming the
//         field).
inline void RefuseOutputInsideExamples(const std::string& option, const std::filesystem::path& output,
                                       const std::filesystem::path& dir, const nlohmann::json& index) {
  if (output.empty() || dir.empty() || !IsAtOrInside(output, dir)) return;
  if (!index.is_object() || !index.contains("clips") || !index["clips"].is_array()) return;
  for (const auto& clip : index["clips"]) {
    if (!clip.is_object() || !clip.contains("name") || !clip["name"].is_string()) continue;
    const std::string name = clip["name"].get<std::string>();
    if (!name.empty()) RefuseOutputInsideFolder(option, output, dir / name, "the example folder");
  }
}

// As above, reading the index from `dir` (empty: no dataset); a dataset whose index cannot be read
// is left to the verb's own reading of it, which names what is wrong.
inline void RefuseOutputInsideExamples(const std::string& option, const std::filesystem::path& output,
                                       const std::filesystem::path& dir) {
  if (output.empty() || dir.empty() || !IsAtOrInside(output, dir)) return;
  nlohmann::json index;
  try {
    index = data::ReadIndex(dir.string());
  } catch (const std::exception&) {
    return;
  }
  RefuseOutputInsideExamples(option, output, dir, index);
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_DATASET_OUTPUTS_H_
