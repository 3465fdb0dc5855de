// Conversions between ROS messages and the ROS-free clip buffer core (src/sensors/clip_*).
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_CLIP_CONVERSIONS_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_CLIP_CONVERSIONS_H_

#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <clothwind/Clip.h>
#include <clothwind/WindMeasurement.h>

#include "sensors/clip_pipeline.h"

namespace clothwind::ros_bridge {

// Wraps an Image message's pixels as a cv::Mat: no copy for the layouts the clip core reads
// (mono8, mono16 little-endian, bgr8, rgb8, bgra8, rgba8; the view is valid while `msg` lives);
// any other layout cv_bridge knows (the Bayer mosaics of industrial cameras, the YUV 4:2:2 of
// UVC ones, 16-bit colour, big-endian 16-bit grey) is converted by it to bgr8, a copy the view
// owns.
// Inputs:
//   msg  an image
// Outputs:
//   view      msg.height x msg.width matrix
//   encoding  its layout
// Throws std::invalid_argument naming the field (encoding, step, data size) that is wrong.
void ImageView(const sensor_msgs::Image& msg, cv::Mat* view, sensors::ClipSourceEncoding* encoding);

// The label reading of a WindMeasurement: its stamp, speed and direction; a reading flagged
// invalid gets a NaN speed (the labeller skips it).
sensors::LabelReading ToLabelReading(const clothwind::WindMeasurement& msg);

// A labelled clip as a clothwind/Clip message.
// Inputs:
//   clip      labelled clip (num_frames frames of size x size, all mono8 or all bgr8)
//   frame_id       the camera's optical frame
//   wind_frame_id  the frame of the label's mean direction (sensors::WindDirectionFrameGate)
clothwind::Clip ToClipMsg(const sensors::LabelledClip& clip, const std::string& frame_id,
                          const std::string& wind_frame_id = "");

// A clip frame as an Image message holding a copy of it: mono8 for CV_8UC1, bgr8 for CV_8UC3.
sensor_msgs::Image ClipFrameImageMsg(const cv::Mat& image, const std_msgs::Header& header);

// The camera_info facts worth keeping with a recorded clip (size, K, D, distortion model).
nlohmann::json CameraInfoJson(const sensor_msgs::CameraInfo& info);

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_CLIP_CONVERSIONS_H_
