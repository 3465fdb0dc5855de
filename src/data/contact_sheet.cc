#include "data/contact_sheet.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/atomic_file.h"
#include "common/dataset_names.h"
#include "common/image_file.h"
#include "data/dataset_index.h"
#include "render/sensor_model.h"

namespace clothwind::data {

namespace fs = std::filesystem;

namespace {

// The file name of frame k from a printf-style pattern such as "%03d.jpg".
std::string FrameFile(const std::string& pattern, int k) {
  char name[256];
  std::snprintf(name, sizeof(name), pattern.c_str(), k);
  return name;
}

void Label(cv::Mat& tile, const std::string& text, int y, double scale) {
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, font, scale, 1, &baseline);
  cv::rectangle(tile, cv::Point(0, y - size.height - 3), cv::Point(size.width + 6, y + baseline),
                cv::Scalar(0, 0, 0), cv::FILLED);
  cv::putText(tile, text, cv::Point(3, y - 1), font, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
}

}  // namespace

cv::Mat MakeContactSheet(const std::string& dir, const nlohmann::json& index,
                         const ContactSheetOptions& o, const std::function<void(int, int)>& progress) {
  if (o.max_tiles < 1 || o.tile < 32) throw std::invalid_argument("contact sheet: max_tiles >= 1, tile >= 32");
  struct Item {
    std::string name;
    double wind;
  };
  std::vector<Item> items;
  const std::string index_path = (fs::path(dir) / "index.json").string();
  if (!index.contains("clips") || !index["clips"].is_array())
    throw std::runtime_error(index_path + ": field \"clips\" must be an array");
  for (size_t i = 0; i < index["clips"].size(); ++i) {
    const nlohmann::json& c = index["clips"][i];
    const std::string where = index_path + ": clips[" + std::to_string(i) + "]";
    // A folder of this dataset, not a path that leads out of it ("../other", "/tmp/x").
    if (!c.is_object() || !c.contains("name") || !c["name"].is_string())
      throw std::runtime_error(where + ".name must be a string");
    const std::string name = c["name"].get<std::string>();
    if (!ValidClipName(name))
      throw std::runtime_error(where + ".name must be a folder name, got \"" + name + "\"");
    const bool has_wind = c.contains("wind_speed") && c["wind_speed"].is_number();
    items.push_back({name, has_wind ? c["wind_speed"].get<double>() : NAN});
  }
  if (items.empty()) return cv::Mat();
  // Clips without a wind (a recording's unlabelled ones) last: `<` on NaN is no ordering at all.
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (std::isnan(a.wind) || std::isnan(b.wind)) return !std::isnan(a.wind) && std::isnan(b.wind);
    return a.wind < b.wind;
  });
  // Evenly spaced over the sorted list: the slowest and the fastest are always shown.
  std::vector<Item> shown;
  const int n = std::min<int>(o.max_tiles, static_cast<int>(items.size()));
  for (int k = 0; k < n; ++k) {
    const size_t i = n == 1 ? 0 : static_cast<size_t>(std::lround(k * (items.size() - 1.0) / (n - 1)));
    shown.push_back(items[i]);
  }
  const int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const int rows = (n + cols - 1) / cols;
  cv::Mat sheet(rows * o.tile, cols * o.tile, CV_8UC3, cv::Scalar(40, 40, 40));
  if (progress) progress(0, n);
  for (int k = 0; k < n; ++k) {
    const fs::path folder = fs::path(dir) / shown[k].name;
    const nlohmann::json label = ReadLabel((folder / "label.json").string());
    const int middle = label["num_frames"].get<int>() / 2;
    const std::string file = (folder / FrameFile(label["frame_pattern"].get<std::string>(), middle)).string();
    std::string why;
    const cv::Mat frame = common::ReadImageFile(file, cv::IMREAD_COLOR, &why);
    if (frame.empty()) throw std::runtime_error("contact sheet: cannot read " + file + " (" + why + ")");
    cv::Mat tile;
    cv::resize(frame, tile, cv::Size(o.tile, o.tile), 0, 0, cv::INTER_AREA);
    char wind[32];
    if (std::isnan(shown[k].wind))
      std::snprintf(wind, sizeof(wind), "no wind");
    else
      std::snprintf(wind, sizeof(wind), "%.1f m/s", shown[k].wind);
    Label(tile, wind, 16, 0.5);
    Label(tile, shown[k].name, o.tile - 4, 0.35);
    tile.copyTo(sheet(cv::Rect((k % cols) * o.tile, (k / cols) * o.tile, o.tile, o.tile)));
    if (progress) progress(k + 1, n);
  }
  return sheet;
}

bool WriteContactSheet(const std::string& dir, const nlohmann::json& index, const std::string& path,
                       const ContactSheetOptions& options, const std::function<void(int, int)>& progress) {
  const cv::Mat sheet = MakeContactSheet(dir, index, options, progress);
  if (sheet.empty()) return false;
  // Its folder again, if it went while the tiles were read (another run sharing a new folder took
  // it away, empty, on failing: tools/output_paths.h RemakeFolderFor); a failure is the write's.
  {
    std::error_code ec;
    const std::filesystem::path folder = std::filesystem::absolute(path, ec).parent_path();
    if (!ec) std::filesystem::create_directories(folder, ec);
  }
  RemoveStaleTemporariesOf(path);  // a killed run's sheet.png.tmp-<pid> stayed beside it for ever
  render::WriteFrameAtomic(path, sheet);
  return true;
}

}  // namespace clothwind::data
