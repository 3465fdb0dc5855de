// Where over the rendering parameters ζ a wind network errs: an evaluation's clips grouped by the
// camera's elevation, azimuth and distance and by the flag's design, each group with Table 1's
// metrics. The speed bands of `clothwind eval` say at which winds a model errs; this says from
// which views and on which textures, which is where a camera in the field can be placed better.
#ifndef CLOTHWIND_LEARN_VIEW_BREAKDOWN_H_
#define CLOTHWIND_LEARN_VIEW_BREAKDOWN_H_

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "learn/evaluate.h"

namespace clothwind::learn {

// What a simulated clip's label.json says about its view (its "zeta" object, docs/dataset.md).
struct ClipView {
  // [deg] angle above the horizontal at which the camera sees the mesh's centre at rest
  // (render::MeshCentre, height mesh_height + mesh_width / mesh_aspect_ratio / 2):
  // atan2(centre height - camera_height, camera_radius). FlagSim's cameras: about 20-55.
  double elevation_deg = 0;
  double angle_deg = 0;     // [deg] |camera_angle_deg|: off the side-on view, either side
  double radius_m = 0;      // [m] camera_radius, horizontal distance to the mesh's centre
  std::string texture;      // texture_name: the flag design or fabric
};

// Reads the view of a simulated clip from its label.json.
// Throws std::runtime_error naming the file and the zeta field that is missing or not a number
// (a real clip's label has no zeta).
ClipView ReadClipView(const std::filesystem::path& label_json);

// Metrics of the examples whose key lies in [lo, hi).
struct BinMetrics {
  double lo = 0, hi = 0;
  Metrics metrics;
};

// Metrics of the examples sharing a name.
struct NamedMetrics {
  std::string name;
  Metrics metrics;
};

// Bins of `width` from width * floor(min key / width) to past the largest key, each with the
// metrics of its examples; only bins that hold examples are returned, in order.
// Inputs: key, truth, predicted  [n], same length; width > 0 (key's unit).
// Throws std::invalid_argument for sizes that differ or width <= 0.
std::vector<BinMetrics> ComputeBinnedMetrics(const std::vector<double>& key, const std::vector<double>& truth,
                                             const std::vector<double>& predicted, double width);

struct ViewBreakdown {
  std::vector<BinMetrics> elevation;  // kElevationBin wide [deg]
  std::vector<BinMetrics> angle;      // kAngleBin wide [deg]
  std::vector<BinMetrics> radius;     // kRadiusBin wide [m]
  std::vector<NamedMetrics> texture;  // by name, sorted by RMSE, worst first
};

inline constexpr double kElevationBin = 5.0;  // [deg]
inline constexpr double kAngleBin = 5.0;      // [deg]
inline constexpr double kRadiusBin = 0.5;     // [m]

// Groups an evaluation's examples by their views.
// Inputs: result  truth, predicted [n]; views [n], views[i] the view of result's example i.
// Throws std::invalid_argument when the sizes differ.
ViewBreakdown BreakDownByView(const EvalResult& result, const std::vector<ClipView>& views);

// Reads the view of every example of `result` (label.json in result.dirs) and groups them.
// Throws std::runtime_error as ReadClipView, for the first clip without a view.
ViewBreakdown BreakDownByView(const EvalResult& result);

// {"camera_elevation_deg": [{"lo", "hi", "rmse", "acc05", "bias", "count"}, ...],
//  "camera_angle_deg": [...], "camera_radius_m": [...], "texture": [{"name", "rmse", ...}, ...]}.
nlohmann::json ViewBreakdownJson(const ViewBreakdown& breakdown);

// One line per group, under a heading per parameter.
std::string ViewBreakdownTable(const ViewBreakdown& breakdown);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_VIEW_BREAKDOWN_H_
