#include "ros_bridge/image_conversions.h"

#include <cstring>
#include <stdexcept>

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

sensor_msgs::CameraInfoPtr CameraInfoFor(const sensor_msgs::CameraInfo& calibration,
                                         const sensor_msgs::Image& image, bool* size_mismatch) {
  auto info = boost::make_shared<sensor_msgs::CameraInfo>();
  const bool calibrated = calibration.width > 0 && calibration.height > 0;
  const bool matches = calibration.width == image.width && calibration.height == image.height;
  if (size_mismatch) *size_mismatch = calibrated && !matches;
  if (calibrated && matches) *info = calibration;
  info->header = image.header;
  info->width = image.width;
  info->height = image.height;
  return info;
}

}  // namespace clothwind::ros_bridge
