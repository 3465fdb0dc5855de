// Conversions between clothwind/Clip, clothwind/WindEstimate, sensor_msgs/Image and the
// ROS-free wind networks (src/learn/predictor.h), for sdn_node.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_SDN_CONVERSIONS_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_SDN_CONVERSIONS_H_

#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <sensor_msgs/Image.h>

#include <clothwind/Clip.h>
#include <clothwind/WindEstimate.h>

#include "learn/predictor.h"

namespace clothwind::ros_bridge {

// The frames of a Clip as num_frames images viewing msg.data (no copy: valid while `msg` lives):
// CV_8UC1 for a mono8 clip, CV_8UC3 BGR for a bgr8 one. Throws std::invalid_argument naming the field that is inconsistent (encoding,
// num_frames, width/height, data length, frame_stamps count).
std::vector<cv::Mat> ClipFrames(const clothwind::Clip& msg);

// The estimate of one clip.
// Inputs:
//   clip        the clip it came from (stamps, sequence, frame_id, anemometer label)
//   prediction  speed and its standard deviation [m/s]
//   latency     seconds from receiving the clip to publishing [s]
//   model       model name for the message
// The header stamp is the clip's last frame stamp (the clip's header stamp when it has none);
// reference_speed is the clip's wind_mean, NaN when no anemometer reading fell in its window.
clothwind::WindEstimate ToWindEstimate(const clothwind::Clip& clip, const learn::Prediction& prediction,
                                       double latency, const std::string& model);

// A bgr8 Image message holding a copy of `bgr` (CV_8UC3).
sensor_msgs::ImagePtr BgrImageMsg(const cv::Mat& bgr, const std_msgs::Header& header);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_SDN_CONVERSIONS_H_
