#include "ros_bridge/image_conversions.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include <boost/make_shared.hpp>

namespace clothwind::ros_bridge {

ros::Time RosTimeFromNs(int64_t stamp_ns) {
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(stamp_ns < 0 ? 0 : stamp_ns));
  return t;
}

sensor_msgs::ImagePtr ToImageMsg(const sensors::Frame& frame, const std::string& frame_id) {
  const cv::Mat& image = frame.image;
  int channels = 0;
  if (frame.encoding == "mono8" && image.type() == CV_8UC1) channels = 1;
  if (frame.encoding == "bgr8" && image.type() == CV_8UC3) channels = 3;
  if (channels == 0) {
    throw std::invalid_argument("frame encoding '" + frame.encoding +
                                "' does not match its image type (expected mono8 with CV_8UC1 "
                                "or bgr8 with CV_8UC3)");
  }
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.stamp = RosTimeFromNs(frame.stamp_ns);
  msg->header.frame_id = frame_id;
  msg->height = static_cast<uint32_t>(image.rows);
  msg->width = static_cast<uint32_t>(image.cols);
  msg->encoding = frame.encoding;
  msg->is_bigendian = 0;
  msg->step = static_cast<uint32_t>(image.cols * channels);
  msg->data.resize(static_cast<size_t>(msg->step) * image.rows);
  for (int r = 0; r < image.rows; ++r) {
    std::memcpy(msg->data.data() + static_cast<size_t>(r) * msg->step, image.ptr(r), msg->step);
  }
  return msg;
}

namespace {

// "" when every value of the calibration's K, D, R and P is finite, else the first that is not.
template <typename Values>
std::string FirstNonFinite(const char* name, const Values& values) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return std::string(name) + "[" + std::to_string(i) + "] is " + std::to_string(values[i]);
  }
  return "";
}

std::string NonFiniteValue(const sensor_msgs::CameraInfo& c) {
  for (const std::string& found : {FirstNonFinite("K", c.K), FirstNonFinite("D", c.D), FirstNonFinite("R", c.R),
                                   FirstNonFinite("P", c.P)}) {
    if (!found.empty()) return found;
  }
  return "";
}

}  // namespace

sensor_msgs::CameraInfoPtr CameraInfoFor(const sensor_msgs::CameraInfo& calibration,
                                         const sensor_msgs::Image& image, std::string* unused_reason) {
  auto info = boost::make_shared<sensor_msgs::CameraInfo>();
  std::string reason;
  if (calibration.width > 0 && calibration.height > 0) {
    const std::string non_finite = NonFiniteValue(calibration);
    if (calibration.width != image.width || calibration.height != image.height) {
      reason = "the calibration (" + std::to_string(calibration.width) + "x" + std::to_string(calibration.height) +
               ") is for another size than the images (" + std::to_string(image.width) + "x" +
               std::to_string(image.height) + ")";
    } else if (!non_finite.empty()) {
      reason = "the calibration's " + non_finite;
    } else {
      *info = calibration;
    }
  }
  if (unused_reason) *unused_reason = reason;
  info->header = image.header;
  info->width = image.width;
  info->height = image.height;
  return info;
}

}  // namespace clothwind::ros_bridge
