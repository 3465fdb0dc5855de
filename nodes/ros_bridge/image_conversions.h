// Conversions between the ROS-free frame sources (src/sensors/frame_source*.h) and ROS images.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_IMAGE_CONVERSIONS_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_IMAGE_CONVERSIONS_H_

#include <cstdint>
#include <string>

#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "sensors/frame_source.h"

namespace clothwind::ros_bridge {

// ROS time from nanoseconds since the Unix epoch (exact, no floating point).
ros::Time RosTimeFromNs(int64_t stamp_ns);

// A frame as an Image message (pixels copied, rows packed: step = width * channels).
// Inputs:
//   frame     image CV_8UC1 (mono8) or CV_8UC3 (bgr8), encoding and stamp [ns]
//   frame_id  the camera's optical frame (REP 103: z forward, x right, y down)
// Throws std::invalid_argument if the image type does not match the encoding.
sensor_msgs::ImagePtr ToImageMsg(const sensors::Frame& frame, const std::string& frame_id);

// The camera_info to publish with an image: the calibration when its size matches the image
// and its K, D, R and P are finite, otherwise an uncalibrated info (zero K, D, R, P) carrying only
// the image size. A calibration with NaN in it came through set_camera_info, which
// camera_info_manager answers without checking values: passed on, it would poison every
// consumer's projection.
// Inputs:
//   calibration  what camera_info_manager holds (width/height 0 when uncalibrated)
//   image        the Image message it goes with (header and size are copied)
// Outputs:
//   unused_reason  why a calibration that exists was left out ("" when it is used or when there is
//                  none; may be null)
sensor_msgs::CameraInfoPtr CameraInfoFor(const sensor_msgs::CameraInfo& calibration,
                                         const sensor_msgs::Image& image, std::string* unused_reason);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_IMAGE_CONVERSIONS_H_
