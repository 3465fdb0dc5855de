// Frame files a verb's earlier run left in its --out folder: a shorter rerun overwrites frames
// 0..n-1 and leaves n, n+1, ... behind, which readers that go on until a frame is missing
// (render's OBJ sequence, a folder source) then take for part of the new run.
#ifndef CLOTHWIND_TOOLS_STALE_FRAMES_H_
#define CLOTHWIND_TOOLS_STALE_FRAMES_H_

#include <cstdio>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>

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

// The frame number of a name printf's "%0<digits>d" followed by `suffix` gives ("0012_00.obj":
// 4, "_00.obj" gives 12; "1000.png": 3, ".png" gives 1000, as frame 1000 is named); nullopt for
// any other name. (Names of 1000 frames and more used to be missed, and left behind as stale.)
inline std::optional<int> FrameNumber(const std::string& name, int digits, const std::string& suffix) {
  if (name.size() < static_cast<size_t>(digits) + suffix.size() ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  const std::string number = name.substr(0, name.size() - suffix.size());
  if (number.size() > 9) return std::nullopt;
  int n = 0;
  for (char c : number) {
    if (c < '0' || c > '9') return std::nullopt;
    n = n * 10 + (c - '0');
  }
  char printed[16];
  std::snprintf(printed, sizeof printed, "%0*d", digits, n);
  if (number != printed) return std::nullopt;  // "0012.jpg" is no frame of "%03d"
  return n;
}

// The frame and cloth of a name ArcSim's "%04d_%02d.obj" gives ("0012_01.obj": 12 and 1; frames of
// 10000 and more, cloths of 100 and more, as printf names them); nullopt for any other name.
inline std::optional<std::pair<int, int>> ObjFrameAndCloth(const std::string& name) {
  const std::string suffix = ".obj";
  if (name.size() <= suffix.size() || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  const std::string stem = name.substr(0, name.size() - suffix.size());
  const size_t underscore = stem.rfind('_');
  if (underscore == std::string::npos) return std::nullopt;
  const auto frame = FrameNumber(stem.substr(0, underscore), 4, "");
  const auto cloth = FrameNumber(stem.substr(underscore + 1), 2, "");
  if (!frame || !cloth) return std::nullopt;
  return std::make_pair(*frame, *cloth);
}

// Whether `name` is a trajectory `clothwind simulate` writes: trajectory.cwtraj (cloth 0) or
// trajectory_<c>.cwtraj (cloth c >= 1, no leading zeros).
inline bool IsSimulateTrajectory(const std::string& name) {
  if (name == "trajectory.cwtraj") return true;
  const std::string prefix = "trajectory_", suffix = ".cwtraj";
  if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const auto cloth = FrameNumber(name.substr(prefix.size(), name.size() - prefix.size() - suffix.size()), 1, "");
  return cloth && *cloth >= 1;
}

}  // namespace clothwind::tools

#endif  // CLOTHWIND_TOOLS_STALE_FRAMES_H_
