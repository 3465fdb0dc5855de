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
#include "sensors/clip_pipeline.h"

namespace clothwind::ros_bridge {

// Bounds of a Clip message's sizes: the clip buffer's (sensors/clip_pipeline.h).
constexpr uint32_t kMaxClipSide = sensors::kMaxClipSide;
constexpr uint32_t kMaxClipFrames = sensors::kMaxClipFrames;
// The smallest clip sdn_node reads [px a side] (the clip buffer makes none smaller).
constexpr uint32_t kMinClipSide = sensors::kMinClipSide;

// The frames of a Clip as num_frames images viewing msg.data (no copy: valid while `msg` lives):
// CV_8UC1 for a mono8 clip, CV_8UC3 BGR for a bgr8 one. Throws std::invalid_argument naming the
// field that is inconsistent (encoding, num_frames, width/height out of 1..kMaxClipSide or
// 1..kMaxClipFrames, width and height unequal (a clip is square, msg/Clip.msg) or under
// kMinClipSide, data length, frame_stamps count, frame_stamps not strictly increasing, a
// first frame stamped 0).
std::vector<cv::Mat> ClipFrames(const clothwind::Clip& msg);

// Throws std::invalid_argument naming Clip.frame_rate when it is not within 1 % of `model_rate`
// [Hz], the rate the model was trained at (its spectra are in Hz), and naming Clip.frame_stamps
// when two consecutive stamps are not 1 / frame_rate apart within 10 %.
void CheckClipFrameRate(const clothwind::Clip& msg, double model_rate);

// The stamp of the clip's frame i: frame_stamps[i], or, for a clip without frame_stamps,
// header.stamp (its first frame's) plus i / frame_rate.
ros::Time ClipFrameStamp(const clothwind::Clip& clip, uint32_t i);

// The stamp of the clip's last frame: frame_stamps.back(), or, for a clip without frame_stamps,
// header.stamp (its first frame's) plus (num_frames - 1) / frame_rate.
// Both throw std::invalid_argument (a malformed clip) when that sum is outside ROS time.
ros::Time ClipEnd(const clothwind::Clip& clip);

// The estimate of one clip.
// Inputs:
//   clip        the clip it came from (stamps, sequence, frame_id, anemometer label)
//   prediction  speed and its standard deviation [m/s]
//   latency     seconds from taking the clip off the queue to publishing [s]
//   model       model name for the message
//   frames_read the frames the model read, the clip's last ones (0: all of them)
// The header stamp is the clip's last frame stamp (ClipEnd), clip_start the first frame read's;
// reference_speed is the clip's wind_mean, NaN when no anemometer reading fell in its window.
clothwind::WindEstimate ToWindEstimate(const clothwind::Clip& clip, const learn::Prediction& prediction,
                                       double latency, const std::string& model, uint32_t frames_read = 0);

// A bgr8 Image message holding a copy of `bgr` (CV_8UC3).
sensor_msgs::ImagePtr BgrImageMsg(const cv::Mat& bgr, const std_msgs::Header& header);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_SDN_CONVERSIONS_H_
