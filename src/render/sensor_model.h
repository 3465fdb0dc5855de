#ifndef CLOTHWIND_RENDER_SENSOR_MODEL_H_
#define CLOTHWIND_RENDER_SENSOR_MODEL_H_

#include <cstdint>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace clothwind::render {

// What happens between the scene's light and the saved frame in a real camera, with each
// effect switchable (all off by default, which gives exactly Develop() of one render) for the
// sim-to-real work: exposure motion blur, sensor noise, JPEG compression.
struct SensorModelParams {
  // Exposure motion blur: the caller renders `subframes` meshes spread over the exposure time
  // and the model averages their radiance. Off: only the middle sub-frame is used, index n / 2
  // of n, so of an even count the later of the two middle ones (frames made so stay as they are).
  bool motion_blur = false;
  // How many sub-frames the caller should render when motion_blur is on, 1..kMaxSubframes.
  int subframes = 1;
  static constexpr int kMaxSubframes = 64;  // 0.6 ms apart over a 1/25 s exposure: smooth

  // Noise on the developed (display-linear, 0..1) signal y: Gaussian with variance
  // y / full_well (shot noise; full_well = photo-electrons at white) + read_noise^2.
  bool noise = false;
  double full_well = 4000.0;  // [1, 1e12]: below one electron at white is no sensor
  double read_noise = 0.004;  // [0, 1]: 1 is the whole display range

  // JPEG: 0 = off; 1..100 encodes and decodes the frame at that quality (the seed's data are
  // JPEG frames, so a learner sees block artefacts unless trained without).
  int jpeg_quality = 0;
};

nlohmann::json ToJson(const SensorModelParams& s);
// Throws std::invalid_argument naming a missing/mistyped field or an out-of-range value.
SensorModelParams SensorModelParamsFromJson(const nlohmann::json& j);
// Throws std::invalid_argument naming the first field outside its range (see the struct) and
// the range: subframes 1..kMaxSubframes, full_well [1, 1e12], read_noise [0, 1] (finite),
// jpeg_quality 0..100.
void ValidateSensorModelParams(const SensorModelParams& s);

// Turns the radiance of one frame into its 8-bit image.
// Inputs:
//   linear_subframes  one or more radiance images (CV_32FC3 RGB, equal sizes) spread over the
//                     exposure, in time order; without motion_blur only the one at index
//                     size / 2 is used (of an even count, the later middle one)
//   s                 the effects (validated: ValidateSensorModelParams)
//   seed              noise seed (e.g. HashSeed(clip seed, frame index))
// Returns CV_8UC3 (B,G,R order). Throws std::invalid_argument on empty or mismatched input or
// invalid s.
cv::Mat ApplySensorModel(const std::vector<cv::Mat>& linear_subframes,
                         const SensorModelParams& s, uint64_t seed);

// Encodes an 8-bit frame as ".jpg" (quality 1..100) or ".png" bytes.
std::vector<uint8_t> EncodeFrame(const cv::Mat& bgr8, const std::string& ext, int jpeg_quality = 95);

// Whether WriteFrameAtomic can write `path`: its extension, in any case, is .jpg, .jpeg or .png.
bool IsFrameFileName(const std::string& path);

// Writes an 8-bit frame atomically (temporary name in the same folder, then rename); the
// format follows the extension of `path` (.jpg/.jpeg/.png). Throws std::runtime_error naming
// the path on failure.
void WriteFrameAtomic(const std::string& path, const cv::Mat& bgr8, int jpeg_quality = 95);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_SENSOR_MODEL_H_
