#include "ros_bridge/clip_conversions.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/image_encodings.h>

namespace clothwind::ros_bridge {

namespace {

// Whether the clip core reads `msg`'s layout as it is (ParseClipSourceEncoding; mono16 only in
// this machine's byte order, little-endian).
bool ReadAsItIs(const sensor_msgs::Image& msg) {
  try {
    const sensors::ClipSourceEncoding e = sensors::ParseClipSourceEncoding(msg.encoding);
    return !(e == sensors::ClipSourceEncoding::kMono16 && msg.is_bigendian);
  } catch (const std::invalid_argument&) {
    return false;
  }
}

// mono16 or its other name 16UC1 (ParseClipSourceEncoding's kMono16).
bool IsMono16(const std::string& encoding) {
  try {
    return sensors::ParseClipSourceEncoding(encoding) == sensors::ClipSourceEncoding::kMono16;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

}  // namespace

void ImageView(const sensor_msgs::Image& msg, cv::Mat* view, sensors::ClipSourceEncoding* encoding) {
  if (msg.width == 0 || msg.height == 0) throw std::invalid_argument("image is empty (width or height 0)");
  // Sizes checked in 64 bits before anything reads the data: cv_bridge checks height * step in
  // 32 bits, which wraps (65537 x 65536 is 65536), and a crafted Bayer image then read 4 GB past
  // its buffer (clip_buffer died with SIGSEGV).
  if (msg.data.size() < static_cast<size_t>(msg.step) * msg.height)
    throw std::invalid_argument("image data has " + std::to_string(msg.data.size()) + " bytes, expected step * height = " +
                                std::to_string(static_cast<size_t>(msg.step) * msg.height));
  if (msg.is_bigendian && IsMono16(msg.encoding)) {
    // A 16-bit camera sending the most significant byte first (GigE cameras may): cv_bridge
    // refused it on the way to bgr8, so its frames were dropped. Swapped into a mono16 copy.
    if (msg.step < static_cast<size_t>(msg.width) * 2)
      throw std::invalid_argument("image step " + std::to_string(msg.step) + " < width * pixel size " +
                                  std::to_string(static_cast<size_t>(msg.width) * 2));
    cv::Mat swapped(static_cast<int>(msg.height), static_cast<int>(msg.width), CV_16UC1);
    for (uint32_t y = 0; y < msg.height; ++y) {
      const uint8_t* in = msg.data.data() + static_cast<size_t>(y) * msg.step;
      uint16_t* out = swapped.ptr<uint16_t>(static_cast<int>(y));
      for (uint32_t x = 0; x < msg.width; ++x) out[x] = static_cast<uint16_t>(in[2 * x] << 8 | in[2 * x + 1]);
    }
    *view = swapped;
    *encoding = sensors::ClipSourceEncoding::kMono16;
    return;
  }
  if (!ReadAsItIs(msg)) {
    // cv_bridge's conversions (debayering, YUV, depth and byte order) rather than our own.
    // OpenCV converts YUV 4:2:2 a pair of pixels (four bytes) at a time: with an odd width and
    // packed rows it read two bytes past the image's data.
    if ((msg.encoding == "yuv422" || msg.encoding == "yuv422_yuy2") && msg.width % 2 != 0)
      throw std::invalid_argument("image encoding '" + msg.encoding +
                                  "' needs an even width (two pixels share their colour), got " +
                                  std::to_string(msg.width));
    int bytes_per_pixel = 1;  // an encoding sensor_msgs does not know: cv_bridge refuses it below
    try {
      bytes_per_pixel = std::max(1, sensor_msgs::image_encodings::numChannels(msg.encoding) *
                                        sensor_msgs::image_encodings::bitDepth(msg.encoding) / 8);
    } catch (const std::exception&) {
    }
    if (msg.step < static_cast<size_t>(msg.width) * std::max(1, bytes_per_pixel))
      throw std::invalid_argument("image step " + std::to_string(msg.step) + " < width * pixel size " +
                                  std::to_string(static_cast<size_t>(msg.width) * bytes_per_pixel));
    try {
      *view = cv_bridge::toCvCopy(msg, sensor_msgs::image_encodings::BGR8)->image;
    } catch (const cv_bridge::Exception& e) {
      throw std::invalid_argument("image encoding '" + msg.encoding + "' not supported (" + e.what() +
                                  "); expected mono8, mono16, bgr8, rgb8, bgra8, rgba8 or one cv_bridge "
                                  "converts to bgr8 (bayer_*, yuv422, 16-bit colour)");
    } catch (const cv::Exception& e) {
      throw std::invalid_argument("image encoding '" + msg.encoding + "': cannot convert (" + e.err + ")");
    }
    *encoding = sensors::ClipSourceEncoding::kBgr8;
    return;
  }
  *encoding = sensors::ParseClipSourceEncoding(msg.encoding);
  const int type = sensors::ClipSourceCvType(*encoding);
  const size_t row_bytes = static_cast<size_t>(msg.width) * CV_ELEM_SIZE(type);
  if (msg.step < row_bytes)
    throw std::invalid_argument("image step " + std::to_string(msg.step) + " < width * pixel size " +
                                std::to_string(row_bytes));
  *view = cv::Mat(static_cast<int>(msg.height), static_cast<int>(msg.width), type,
                  const_cast<uint8_t*>(msg.data.data()), msg.step);
}

sensors::LabelReading ToLabelReading(const clothwind::WindMeasurement& msg) {
  sensors::LabelReading r;
  r.stamp = msg.header.stamp.toSec();
  // A speed WindMeasurement does not allow (negative, or beyond any wind: -50 and 1e300 were
  // averaged into a minute of labels) is skipped as an invalid reading is.
  r.speed = msg.valid && msg.speed >= 0 && msg.speed <= 150 ? msg.speed : std::numeric_limits<double>::quiet_NaN();
  r.direction = msg.direction;
  r.source = msg.source;
  r.frame_id = msg.header.frame_id;
  r.relative = msg.relative;
  return r;
}

clothwind::Clip ToClipMsg(const sensors::LabelledClip& c, const std::string& frame_id,
                          const std::string& wind_frame_id) {
  clothwind::Clip msg;
  const auto& frames = c.clip.frames;
  if (frames.empty()) throw std::invalid_argument("clip has no frames");
  msg.header.stamp = ros::Time(frames.front().stamp);
  msg.header.frame_id = frame_id;
  msg.sequence = c.clip.sequence;
  msg.frame_rate = static_cast<float>(c.frame_rate);
  msg.num_frames = static_cast<uint32_t>(frames.size());
  msg.height = static_cast<uint32_t>(frames.front().image.rows);
  msg.width = static_cast<uint32_t>(frames.front().image.cols);
  const bool colour = frames.front().image.type() == CV_8UC3;
  msg.encoding = sensors::ClipFrameEncoding(colour);
  const size_t row_bytes = static_cast<size_t>(msg.width) * (colour ? 3 : 1);
  const size_t frame_bytes = row_bytes * msg.height;
  msg.data.resize(frame_bytes * frames.size());
  for (size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat& img = frames[i].image;
    if (img.type() != sensors::ClipFrameCvType(colour) || static_cast<uint32_t>(img.rows) != msg.height ||
        static_cast<uint32_t>(img.cols) != msg.width)
      throw std::invalid_argument("clip frame " + std::to_string(i) + " is not a " + msg.encoding +
                                  " image of the clip's size");
    uint8_t* dst = msg.data.data() + i * frame_bytes;
    for (int r = 0; r < img.rows; ++r) std::memcpy(dst + r * row_bytes, img.ptr(r), row_bytes);
    msg.frame_stamps.push_back(ros::Time(frames[i].stamp));
  }
  msg.roi.x_offset = c.roi.x;
  msg.roi.y_offset = c.roi.y;
  msg.roi.width = c.roi.size;
  msg.roi.height = c.roi.size;
  msg.roi.do_rectify = false;
  msg.source_width = c.source_width;
  msg.source_height = c.source_height;
  msg.label_window = c.label.window;
  msg.wind_mean = c.label.mean;
  msg.wind_std = c.label.std;
  msg.wind_count = c.label.count;
  msg.wind_direction_mean = c.label.direction_mean;
  msg.wind_direction_frame_id = wind_frame_id;
  return msg;
}

sensor_msgs::Image ClipFrameImageMsg(const cv::Mat& image, const std_msgs::Header& header) {
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3)
    throw std::invalid_argument("ClipFrameImageMsg: expected a CV_8UC1 or CV_8UC3 image");
  const bool colour = image.type() == CV_8UC3;
  sensor_msgs::Image msg;
  msg.header = header;
  msg.height = image.rows;
  msg.width = image.cols;
  msg.encoding = sensors::ClipFrameEncoding(colour);
  msg.is_bigendian = 0;
  msg.step = image.cols * (colour ? 3 : 1);
  msg.data.resize(static_cast<size_t>(image.rows) * msg.step);
  for (int r = 0; r < image.rows; ++r)
    std::memcpy(msg.data.data() + static_cast<size_t>(r) * msg.step, image.ptr(r), msg.step);
  return msg;
}

nlohmann::json CameraInfoJson(const sensor_msgs::CameraInfo& info) {
  return {{"width", info.width},
          {"height", info.height},
          {"frame_id", info.header.frame_id},
          {"distortion_model", info.distortion_model},
          {"D", info.D},
          {"K", std::vector<double>(info.K.begin(), info.K.end())}};
}

}  // namespace clothwind::ros_bridge
