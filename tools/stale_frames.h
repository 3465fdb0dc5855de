// Frame files a verb's earlier run left in its --out folder: a shorter rerun overwrites frames
// 0..n-1 and leaves n, n+1, ... behind, which readers that go on until a frame is missing
// (render's OBJ sequence, a folder source) then take for part of the new run.
#ifndef CLOTHWIND_TOOLS_STALE_FRAMES_H_
#define CLOTHWIND_TOOLS_STALE_FRAMES_H_

#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace clothwind::tools {

// Removes the files in `dir` for which `stale(name)` says so.
// Inputs:
//   dir    the output folder (missing: nothing to do)
//   stale  file name -> whether it is a frame of an earlier run that this run does not rewrite
// Returns how many files were removed.
inline int RemoveStaleFrames(const std::filesystem::path& dir, const std::function<bool(const std::string&)>& stale) {
  namespace fs = std::filesystem;
  int removed = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_regular_file(ec) || !stale(e.path().filename().string())) continue;
    if (fs::remove(e.path(), ec)) ++removed;
  }
  return removed;
}

// The frame number of a name made of `digits` digits, then `suffix` ("0012_00.obj": 4, "_00.obj"
// gives 12); nullopt for any other name.
inline std::optional<int> FrameNumber(const std::string& name, int digits, const std::string& suffix) {
  if (name.size() != static_cast<size_t>(digits) + suffix.size() || name.compare(digits, suffix.size(), suffix) != 0)
    return std::nullopt;
  int n = 0;
  for (int i = 0; i < digits; ++i) {
    if (name[i] < '0' || name[i] > '9') return std::nullopt;
    n = n * 10 + (name[i] - '0');
  }
  return n;
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_STALE_FRAMES_H_
