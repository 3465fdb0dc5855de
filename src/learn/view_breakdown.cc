#include "learn/view_breakdown.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

#include "common/formatted.h"
#include "learn/dataset.h"

namespace clothwind::learn {
namespace fs = std::filesystem;

namespace {

double ZetaNumber(const nlohmann::json& zeta, const char* field, const fs::path& file) {
  if (!zeta.contains(field) || !zeta[field].is_number()) {
    throw std::runtime_error(file.string() + ": zeta." + field + " is missing or not a number");
  }
  return zeta[field].get<double>();
}

nlohmann::json BinsJson(const std::vector<BinMetrics>& bins) {
  nlohmann::json out = nlohmann::json::array();
  for (const BinMetrics& b : bins) {
    nlohmann::json bin = {{"lo", b.lo}, {"hi", b.hi}};
    bin.update(MetricsJson(b.metrics));
    out.push_back(bin);
  }
  return out;
}

void MetricsColumns(std::ostream& s, const Metrics& m) {
  s << std::fixed << std::setprecision(3) << "RMSE " << m.rmse << "  Acc@0.5 " << m.acc05 << "  bias "
    << std::showpos << m.bias << std::noshowpos << "  (" << m.count << ")\n";
}

void BinsTable(std::ostream& s, const std::string& heading, const std::vector<BinMetrics>& bins, int digits,
               const std::string& unit) {
  s << "  by " << heading << ":\n";
  for (const BinMetrics& b : bins) {
    std::ostringstream range;
    range << std::fixed << std::setprecision(digits) << b.lo << "-" << b.hi << " " << unit;
    s << "    " << std::left << std::setw(14) << range.str() << std::right;
    MetricsColumns(s, b.metrics);
  }
}

}  // namespace

ClipView ReadClipView(const fs::path& label_json) {
  const nlohmann::json label = ReadJson(label_json);
  if (!label.contains("zeta") || !label["zeta"].is_object()) {
    throw std::runtime_error(label_json.string() +
                             ": no zeta object (the rendering parameters of a simulated clip; a real clip has none)");
  }
  const nlohmann::json& z = label["zeta"];
  // Within the renderer's ranges (render::ValidateRenderParams; the angle within a turn): a
  // radius of -3 m or 1e300 was binned as it was, into a 300-digit "camera distance" bin, and an
  // angle of 1e300 deg overflowed its bin's index.
  auto in = [&](const char* field, double lo, double hi, const char* range) {
    const double x = ZetaNumber(z, field, label_json);
    if (!(x >= lo && x <= hi))
      throw std::runtime_error(label_json.string() + ": zeta." + field + " is " + Formatted("%g", x) + ", expected " +
                               range);
    return x;
  };
  const double aspect = in("mesh_aspect_ratio", 0.1, 10, "in [0.1, 10]");
  const double width = in("mesh_width", 1e-9, 1e3, "in (0, 1000] m");
  const double centre = in("mesh_height", 0, 1e3, "in [0, 1000] m") + width / aspect / 2;
  ClipView v;
  v.radius_m = in("camera_radius", 0.1, 1e4, "in [0.1, 10000] m");
  v.elevation_deg = std::atan2(centre - in("camera_height", 1e-9, 1e3, "in (0, 1000] m"), v.radius_m) * 180.0 / M_PI;
  v.angle_deg = std::abs(in("camera_angle_deg", -360, 360, "in [-360, 360] deg"));
  if (!z.contains("texture_name") || !z["texture_name"].is_string()) {
    throw std::runtime_error(label_json.string() + ": zeta.texture_name is missing or not a string");
  }
  v.texture = z["texture_name"].get<std::string>();
  return v;
}

std::vector<BinMetrics> ComputeBinnedMetrics(const std::vector<double>& key, const std::vector<double>& truth,
                                             const std::vector<double>& predicted, double width) {
  if (key.size() != truth.size() || truth.size() != predicted.size()) {
    throw std::invalid_argument("ComputeBinnedMetrics: key, truth and predicted differ in size");
  }
  if (!(width > 0)) throw std::invalid_argument("ComputeBinnedMetrics: width must be > 0, got " + std::to_string(width));
  if (key.empty()) return {};
  const double origin = width * std::floor(*std::min_element(key.begin(), key.end()) / width);
  std::map<long, std::pair<std::vector<double>, std::vector<double>>> bins;  // bin index -> truth, predicted
  for (size_t i = 0; i < key.size(); ++i) {
    auto& [t, p] = bins[static_cast<long>(std::floor((key[i] - origin) / width))];
    t.push_back(truth[i]);
    p.push_back(predicted[i]);
  }
  std::vector<BinMetrics> out;
  for (const auto& [index, tp] : bins) {
    out.push_back({origin + index * width, origin + (index + 1) * width, ComputeMetrics(tp.first, tp.second)});
  }
  return out;
}

ViewBreakdown BreakDownByView(const EvalResult& result, const std::vector<ClipView>& views) {
  const size_t n = result.truth.size();
  if (views.size() != n || result.predicted.size() != n) {
    throw std::invalid_argument("BreakDownByView: " + std::to_string(views.size()) + " views for " +
                                std::to_string(n) + " examples");
  }
  std::vector<double> elevation, angle, radius;
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> by_texture;
  for (size_t i = 0; i < n; ++i) {
    elevation.push_back(views[i].elevation_deg);
    angle.push_back(views[i].angle_deg);
    radius.push_back(views[i].radius_m);
    by_texture[views[i].texture].first.push_back(result.truth[i]);
    by_texture[views[i].texture].second.push_back(result.predicted[i]);
  }
  ViewBreakdown b;
  b.elevation = ComputeBinnedMetrics(elevation, result.truth, result.predicted, kElevationBin);
  b.angle = ComputeBinnedMetrics(angle, result.truth, result.predicted, kAngleBin);
  b.radius = ComputeBinnedMetrics(radius, result.truth, result.predicted, kRadiusBin);
  for (const auto& [name, tp] : by_texture) b.texture.push_back({name, ComputeMetrics(tp.first, tp.second)});
  std::stable_sort(b.texture.begin(), b.texture.end(),
                   [](const NamedMetrics& x, const NamedMetrics& y) { return x.metrics.rmse > y.metrics.rmse; });
  return b;
}

ViewBreakdown BreakDownByView(const EvalResult& result) {
  if (result.dirs.size() != result.truth.size()) {
    throw std::invalid_argument("BreakDownByView: the evaluation lists no folder for some examples");
  }
  std::vector<ClipView> views;
  for (const fs::path& dir : result.dirs) views.push_back(ReadClipView(dir / "label.json"));
  return BreakDownByView(result, views);
}

nlohmann::json ViewBreakdownJson(const ViewBreakdown& b) {
  nlohmann::json textures = nlohmann::json::array();
  for (const NamedMetrics& t : b.texture) {
    nlohmann::json entry = {{"name", t.name}};
    entry.update(MetricsJson(t.metrics));
    textures.push_back(entry);
  }
  return {{"camera_elevation_deg", BinsJson(b.elevation)},
          {"camera_angle_deg", BinsJson(b.angle)},
          {"camera_radius_m", BinsJson(b.radius)},
          {"texture", textures}};
}

std::string ViewBreakdownTable(const ViewBreakdown& b) {
  std::ostringstream s;
  BinsTable(s, "camera elevation (to the mesh's centre at rest)", b.elevation, 0, "deg");
  BinsTable(s, "camera angle off side-on, either side", b.angle, 0, "deg");
  BinsTable(s, "camera distance", b.radius, 1, "m");
  s << "  by texture, worst first:\n";
  for (const NamedMetrics& t : b.texture) {
    s << "    " << std::left << std::setw(24) << t.name << std::right;
    MetricsColumns(s, t.metrics);
  }
  return s.str();
}

}  // namespace clothwind::learn
