#include "render/sensor_model.h"

#include "common/atomic_file.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "render/color.h"
#include "common/random.h"

namespace clothwind::render {

nlohmann::json ToJson(const SensorModelParams& s) {
  return nlohmann::json{{"motion_blur", s.motion_blur}, {"subframes", s.subframes},
                        {"noise", s.noise},             {"full_well", s.full_well},
                        {"read_noise", s.read_noise},   {"jpeg_quality", s.jpeg_quality}};
}

SensorModelParams SensorModelParamsFromJson(const nlohmann::json& j) {
  auto field = [&](const char* name) -> const nlohmann::json& {
    if (!j.is_object() || !j.contains(name))
      throw std::invalid_argument(std::string("sensor model: missing field '") + name + "'");
    return j.at(name);
  };
  auto boolean = [&](const char* name) {
    const auto& f = field(name);
    if (!f.is_boolean())
      throw std::invalid_argument(std::string("sensor model: field '") + name +
                                  "' must be true or false, got " + f.dump());
    return f.get<bool>();
  };
  auto number = [&](const char* name) {
    const auto& f = field(name);
    if (!f.is_number())
      throw std::invalid_argument(std::string("sensor model: field '") + name +
                                  "' must be a number, got " + f.dump());
    return f.get<double>();
  };
  auto integer = [&](const char* name) {
    const auto& f = field(name);
    if (!f.is_number_integer() || f.get<int64_t>() < INT32_MIN || f.get<int64_t>() > INT32_MAX)
      throw std::invalid_argument(std::string("sensor model: field '") + name +
                                  "' must be an integer, got " + f.dump());
    return f.get<int>();
  };
  SensorModelParams s;
  s.motion_blur = boolean("motion_blur");
  s.subframes = integer("subframes");
  s.noise = boolean("noise");
  s.full_well = number("full_well");
  s.read_noise = number("read_noise");
  s.jpeg_quality = integer("jpeg_quality");
  ValidateSensorModelParams(s);
  return s;
}

namespace {
void Require(bool ok, const char* field, const std::string& expected, double value) {
  if (!ok) {
    std::ostringstream m;
    m << "sensor model: field '" << field << "' is " << value << ", expected " << expected;
    throw std::invalid_argument(m.str());
  }
}
}  // namespace

void ValidateSensorModelParams(const SensorModelParams& s) {
  // Bounded above: the caller renders `subframes` meshes per frame (2^31 of them, silently), and
  // a huge or non-finite noise made every pixel 0 or 255, or NaN before the 8-bit conversion.
  Require(s.subframes >= 1 && s.subframes <= SensorModelParams::kMaxSubframes, "subframes",
          "in [1, " + std::to_string(SensorModelParams::kMaxSubframes) + "]", s.subframes);
  Require(s.full_well >= 1 && s.full_well <= 1e12, "full_well", "in [1, 1e12] electrons",
          s.full_well);
  Require(s.read_noise >= 0 && s.read_noise <= 1, "read_noise",
          "in [0, 1] (of the display range)", s.read_noise);
  Require(s.jpeg_quality >= 0 && s.jpeg_quality <= 100, "jpeg_quality", "in [0, 100]",
          s.jpeg_quality);
}

cv::Mat ApplySensorModel(const std::vector<cv::Mat>& linear_subframes,
                         const SensorModelParams& s, uint64_t seed) {
  ValidateSensorModelParams(s);
  if (linear_subframes.empty())
    throw std::invalid_argument("ApplySensorModel: no sub-frames given");
  for (const cv::Mat& m : linear_subframes)
    if (m.type() != CV_32FC3 || m.size() != linear_subframes[0].size())
      throw std::invalid_argument(
          "ApplySensorModel: sub-frames must all be CV_32FC3 images of one size");
  cv::Mat radiance;
  if (s.motion_blur && linear_subframes.size() > 1) {
    radiance = cv::Mat::zeros(linear_subframes[0].size(), CV_32FC3);
    for (const cv::Mat& m : linear_subframes) radiance += m;
    radiance /= static_cast<double>(linear_subframes.size());
  } else {
    // The middle one; of an even count the later of the two (kept: frames were made so).
    radiance = linear_subframes[linear_subframes.size() / 2];
  }
  cv::Mat out(radiance.rows, radiance.cols, CV_8UC3);
  for (int y = 0; y < radiance.rows; ++y) {
    const cv::Vec3f* in = radiance.ptr<cv::Vec3f>(y);
    cv::Vec3b* o = out.ptr<cv::Vec3b>(y);
    Rng rng(HashSeed(seed, 0x5e45, static_cast<uint64_t>(y)));
    for (int x = 0; x < radiance.cols; ++x) {
      float c[3];
      for (int k = 0; k < 3; ++k) {
        float v = Tone(in[x][k]);
        if (s.noise) {
          // Box-Muller; one normal per channel.
          const double u1 = std::max(rng.Uniform(), 1e-12), u2 = rng.Uniform();
          const double g = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
          const double sigma = std::sqrt(std::max(v, 0.0f) / s.full_well + s.read_noise * s.read_noise);
          v = static_cast<float>(v + sigma * g);
        }
        c[k] = v;
      }
      o[x] = cv::Vec3b(ToSrgb8(c[2]), ToSrgb8(c[1]), ToSrgb8(c[0]));
    }
  }
  if (s.jpeg_quality > 0) {
    const std::vector<uint8_t> bytes = EncodeFrame(out, ".jpg", s.jpeg_quality);
    out = cv::imdecode(bytes, cv::IMREAD_COLOR);
  }
  return out;
}

std::vector<uint8_t> EncodeFrame(const cv::Mat& bgr8, const std::string& ext, int jpeg_quality) {
  std::vector<int> flags;
  if (ext == ".jpg" || ext == ".jpeg") flags = {cv::IMWRITE_JPEG_QUALITY, std::clamp(jpeg_quality, 1, 100)};
  std::vector<uint8_t> bytes;
  if (!cv::imencode(ext, bgr8, bytes, flags))
    throw std::runtime_error("EncodeFrame: cannot encode a frame as " + ext);
  return bytes;
}

bool IsFrameFileName(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png";
}

void WriteFrameAtomic(const std::string& path, const cv::Mat& bgr8, int jpeg_quality) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (!IsFrameFileName(path))
    throw std::runtime_error("WriteFrameAtomic: '" + path + "' must end in .jpg, .jpeg or .png");
  const std::vector<uint8_t> bytes = EncodeFrame(bgr8, ext == ".png" ? ".png" : ".jpg", jpeg_quality);
  clothwind::WriteFileAtomically(path, bytes.data(), bytes.size());
}

}  // namespace clothwind::render
