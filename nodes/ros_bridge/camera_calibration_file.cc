#include "ros_bridge/camera_calibration_file.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <camera_calibration_parsers/parse_ini.h>
#include <camera_calibration_parsers/parse_yml.h>
#include <yaml-cpp/yaml.h>

namespace clothwind::ros_bridge {
namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool StartsWith(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// What a path that is not a regular file is, for the message.
std::string Kind(const struct stat& st) {
  if (S_ISDIR(st.st_mode)) return "a directory";
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return "a device";
  if (S_ISFIFO(st.st_mode)) return "a pipe";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "not a regular file";
}

// The first key given twice in a mapping of `node` or of any mapping under it, as its path
// ("camera_matrix.data"); "" when none.
std::string KeyGivenTwice(const YAML::Node& node, const std::string& prefix) {
  if (!node.IsMap()) return "";
  std::set<std::string> keys;
  for (const auto& entry : node) {
    const std::string key = prefix + (entry.first.IsScalar() ? entry.first.Scalar() : std::string("(not text)"));
    if (!keys.insert(key).second) return key;
    const std::string below = KeyGivenTwice(entry.second, key + ".");
    if (!below.empty()) return below;
  }
  return "";
}

// One calibration matrix of the YAML; "" when whole. rows/cols < 0: any (D).
std::string CheckMatrix(const YAML::Node& doc, const char* key, int rows, int cols) {
  const YAML::Node m = doc[key];
  if (!m) return "";
  const std::string name = key;
  if (!m.IsMap() || !m["rows"] || !m["cols"] || !m["data"])
    return name + " needs rows, cols and data";
  int r = 0, c = 0;
  try {
    r = m["rows"].as<int>();
    c = m["cols"].as<int>();
  } catch (const YAML::Exception&) {
    return name + ": rows and cols must be whole numbers";
  }
  if (rows >= 0 && (r != rows || c != cols))
    return name + " is " + std::to_string(r) + "x" + std::to_string(c) + ", CameraInfo's is " +
           std::to_string(rows) + "x" + std::to_string(cols);
  if (r < 0 || c < 0) return name + ": rows and cols must be >= 0";
  const YAML::Node data = m["data"];
  if (!data.IsSequence()) return name + ": data must be a list";
  if (static_cast<long>(data.size()) != static_cast<long>(r) * c)
    return name + ": rows x cols is " + std::to_string(r) + "x" + std::to_string(c) + " = " +
           std::to_string(static_cast<long>(r) * c) + " values, data has " + std::to_string(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    try {
      data[i].as<double>();
    } catch (const YAML::Exception&) {
      return name + ": data[" + std::to_string(i) + "] is not a number";
    }
  }
  return "";
}

}  // namespace

std::string CalibrationFilePath(const std::string& resolved_url,
                                const std::function<std::string(const std::string&)>& package_path) {
  const std::string lower = Lower(resolved_url);
  if (StartsWith(lower, "file:///")) return resolved_url.substr(7);  // file://x is no file URL to it either
  if (StartsWith(lower, "package://")) {
    const std::string rest = resolved_url.substr(10);
    const size_t slash = rest.find('/');
    if (slash == std::string::npos) return "";  // camera_info_manager refuses it: no file named
    const std::string folder = package_path(rest.substr(0, slash));
    if (folder.empty()) return "";  // an unknown package: camera_info_manager says so
    return folder + rest.substr(slash);
  }
  return "";
}

std::string CheckCalibrationFile(const std::string& path) {
  if (path.empty()) return "";
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return "";  // no calibration yet: camera_info_manager says so, set_camera_info writes it
    return path + ": " + std::strerror(errno);
  }
  if (!S_ISREG(st.st_mode)) return path + " is " + Kind(st) + ", not a calibration file";
  if (!std::ifstream(path).good()) return path + ": cannot be read";
  const std::string lower = Lower(path);
  if (!EndsWith(lower, ".yaml") && !EndsWith(lower, ".yml")) return "";  // .ini: not read through YAML
  YAML::Node doc;
  try {
    doc = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    return path + " is not YAML: " + e.what();
  }
  if (!doc.IsMap()) return path + " is not a YAML mapping (image_width, camera_matrix, ...)";
  // A key given twice (an edit pasted below the old value), at any depth: the parser took the
  // first without a word, so "image_width: 64" above "image_width: 640" calibrated 640-px frames
  // for 64.
  const std::string twice = KeyGivenTwice(doc, "");
  if (!twice.empty()) return path + ": key " + twice + " is given twice";
  for (const auto& [key, rows, cols] : {std::tuple<const char*, int, int>{"camera_matrix", 3, 3},
                                        {"distortion_coefficients", -1, -1},
                                        {"rectification_matrix", 3, 3},
                                        {"projection_matrix", 3, 4}}) {
    const std::string problem = CheckMatrix(doc, key, rows, cols);
    if (!problem.empty()) return path + ": " + problem;
  }
  // Focal lengths > 0 and image sizes > 0: a camera_matrix with fx = -5 (a sign lost in an edit)
  // was taken, and every consumer then projected through a mirrored camera.
  if (doc["camera_matrix"]) {
    const YAML::Node k = doc["camera_matrix"]["data"];
    if (!(k[0].as<double>() > 0 && k[4].as<double>() > 0))
      return path + ": camera_matrix's fx and fy (data[0], data[4]) must be > 0 [px], got " + k[0].Scalar() + " and " +
             k[4].Scalar();
  }
  for (const char* key : {"image_width", "image_height"}) {
    if (!doc[key]) continue;
    long value = 0;
    try {
      value = doc[key].as<long>();
    } catch (const YAML::Exception&) {
      return path + ": " + key + " must be a whole number of pixels";
    }
    if (value <= 0) return path + ": " + key + " must be > 0 [px], got " + std::to_string(value);
  }
  // The models image_geometry undistorts with: another name (a typo, "plumb_bobb") was taken, and
  // every consumer then rectified with no distortion at all.
  if (doc["distortion_model"]) {
    const YAML::Node model = doc["distortion_model"];
    const std::string name = model.IsScalar() ? model.as<std::string>() : std::string("(not text)");
    if (!name.empty() && name != "plumb_bob" && name != "rational_polynomial" && name != "equidistant")
      return path + ": distortion_model is '" + name +
             "', expected plumb_bob, rational_polynomial, equidistant or empty (no distortion)";
  }
  return "";
}

std::string CalibrationFileText(const std::string& path, const std::string& camera_name,
                                const sensor_msgs::CameraInfo& info) {
  const std::string lower = Lower(path);
  const bool ini = EndsWith(lower, ".ini");
  if (!ini && !EndsWith(lower, ".yaml") && !EndsWith(lower, ".yml"))
    throw std::runtime_error(path + ": expected a .yaml, .yml or .ini file name");
  std::ostringstream text;
  const bool written = ini ? camera_calibration_parsers::writeCalibrationIni(text, camera_name, info)
                           : camera_calibration_parsers::writeCalibrationYml(text, camera_name, info);
  if (!written) throw std::runtime_error(std::string("cannot write the calibration as ") + (ini ? "INI" : "YAML"));
  return text.str();
}

}  // namespace clothwind::ros_bridge
