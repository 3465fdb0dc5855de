// wind_display_node: turns the latest wind estimate and anemometer readings into things rviz
// shows (rviz cannot plot custom scalar messages), for launch/monitor.launch:
//   monitor/wind_markers (visualization_msgs/MarkerArray): a view-facing text, two lines
//     "estimate 3.4 ± 0.3 m/s, 60 s mean 3.6" / "anemometer 3.2 m/s (60 s mean)", and an arrow along the
//     anemometer's latest air velocity (REP 103: where the wind blows TO), 1 m per m/s, in the
//     anemometer's frame (header.frame_id of anemometer/wind, so rviz needs no transform when its
//     fixed frame is that frame);
//   monitor/wind_plot (sensor_msgs/Image, bgr8): estimate (with ±std band) vs anemometer over the
//     last ~plot_window seconds, stamped with the newest input's stamp and the anemometer's frame.
// Inputs: wind/estimate (clothwind/WindEstimate), anemometer/wind (clothwind/WindMeasurement).
// Parameters: ~mean_window [s] (60), ~plot_window [s] (180), ~plot_width/~plot_height [px]
// (640x320), ~rate [Hz] (2), ~frame_id ("" = the anemometer's frame, else this one),
// ~fixed_frame ("" = none): when set, a latched /tf_static places the display frame at this
// frame with the identity transform, so rviz has a fixed frame without a robot's TF tree (the
// monitor does not know where the anemometer is; leave it empty when a real TF tree exists).
// Drawing and averaging are the ROS-free sensors/wind_plot.
#include <cmath>
#include <string>

#include <clothwind/WindEstimate.h>
#include <clothwind/WindMeasurement.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "sensors/wind_plot.h"

namespace {

using clothwind::sensors::WindHistory;
using clothwind::sensors::WindSample;

class WindDisplayNode {
 public:
  WindDisplayNode(ros::NodeHandle nh, ros::NodeHandle pnh)
      : estimates_(1.0), anemometer_(1.0) {
    pnh.param("mean_window", mean_window_, 60.0);
    pnh.param("plot_window", plot_window_, 180.0);
    pnh.param("plot_width", plot_width_, 640);
    pnh.param("plot_height", plot_height_, 320);
    pnh.param<std::string>("frame_id", frame_id_param_, "");
    pnh.param<std::string>("fixed_frame", fixed_frame_, "");
    double rate;
    pnh.param("rate", rate, 2.0);
    if (!(mean_window_ > 0) || !(plot_window_ > 0) || !(rate > 0) || plot_width_ < 160 || plot_height_ < 120) {
      ROS_FATAL("wind_display: ~mean_window, ~plot_window and ~rate must be > 0 and ~plot_width x ~plot_height "
                "at least 160x120 (got %g, %g, %g, %dx%d)", mean_window_, plot_window_, rate, plot_width_,
                plot_height_);
      ros::shutdown();
      return;
    }
    const double span = std::max(mean_window_, plot_window_) + 10.0;
    estimates_ = WindHistory(span);
    anemometer_ = WindHistory(span);
    markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("monitor/wind_markers", 1, true);
    plot_pub_ = nh.advertise<sensor_msgs::Image>("monitor/wind_plot", 1, true);
    if (!fixed_frame_.empty()) tf_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
    estimate_sub_ = nh.subscribe("wind/estimate", 10, &WindDisplayNode::OnEstimate, this);
    wind_sub_ = nh.subscribe("anemometer/wind", 50, &WindDisplayNode::OnWind, this);
    // Redraw on a timer, not per message: the plot scrolls with time even when inputs pause.
    timer_ = nh.createTimer(ros::Duration(1.0 / rate), &WindDisplayNode::Publish, this);
  }

 private:
  void OnEstimate(const clothwind::WindEstimate::ConstPtr& msg) {
    estimates_.Add({msg->header.stamp.toSec(), msg->speed, msg->speed_std});
    last_estimate_ = *msg;
    have_estimate_ = true;
    Touch(msg->header.stamp);
  }

  void OnWind(const clothwind::WindMeasurement::ConstPtr& msg) {
    if (!msg->valid) return;
    anemometer_.Add({msg->header.stamp.toSec(), msg->speed, 0.0});
    last_wind_ = *msg;
    have_wind_ = true;
    Touch(msg->header.stamp);
  }

  // The displays are stamped with the newest input stamp (bag time on replay, so rviz on sim time
  // shows them in step with the images); a stamp going back means the replay restarted.
  void Touch(const ros::Time& stamp) {
    if (stamp > latest_stamp_ || stamp + ros::Duration(5.0) < latest_stamp_) latest_stamp_ = stamp;
  }

  std::string FrameId() const {
    if (!frame_id_param_.empty()) return frame_id_param_;
    if (have_wind_ && !last_wind_.header.frame_id.empty()) return last_wind_.header.frame_id;
    return "anemometer";
  }

  void Publish(const ros::TimerEvent&) {
    if (!have_estimate_ && !have_wind_) return;  // nothing to show yet
    const std::string frame = FrameId();
    if (!fixed_frame_.empty() && frame != tf_child_ && frame != fixed_frame_) PublishFixedFrame(frame);
    const double t_now = latest_stamp_.toSec();
    const double mean = anemometer_.Mean(t_now, mean_window_);
    const double est = have_estimate_ ? last_estimate_.speed : std::nan("");
    const double est_std = have_estimate_ ? last_estimate_.speed_std : std::nan("");

    visualization_msgs::MarkerArray array;
    visualization_msgs::Marker text;
    text.header.stamp = latest_stamp_;
    text.header.frame_id = frame;
    text.ns = "wind_text";
    text.id = 0;
    text.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    text.action = visualization_msgs::Marker::ADD;
    // Beside (above, in a top-down view) the 10 m grid around the anemometer, clear of the arrow.
    text.pose.position.x = 0.0;
    text.pose.position.y = 7.0;
    text.pose.position.z = 1.5;
    text.pose.orientation.w = 1.0;
    text.scale.z = 0.6;  // [m] letter height
    text.color.r = text.color.g = text.color.b = 1.0;
    text.color.a = 1.0;
    const double est_mean = have_estimate_ ? estimates_.Mean(t_now, mean_window_) : std::nan("");
    text.text = clothwind::sensors::WindSummaryText(est, est_std, mean, mean_window_, est_mean);
    const size_t bar = text.text.find(" | ");  // two lines: the 3-D view is narrow beside the images
    if (bar != std::string::npos) text.text.replace(bar, 3, "\n");
    array.markers.push_back(text);

    visualization_msgs::Marker arrow;
    arrow.header = text.header;
    arrow.ns = "anemometer_wind";
    arrow.id = 0;
    arrow.type = visualization_msgs::Marker::ARROW;
    arrow.pose.orientation.w = 1.0;
    const bool has_vector = have_wind_ && std::isfinite(last_wind_.velocity.x) && std::isfinite(last_wind_.velocity.y);
    arrow.action = has_vector ? visualization_msgs::Marker::ADD : visualization_msgs::Marker::DELETE;
    if (has_vector) {
      geometry_msgs::Point tail, tip;
      tip.x = last_wind_.velocity.x;  // 1 m per m/s
      tip.y = last_wind_.velocity.y;
      tip.z = last_wind_.velocity.z;
      arrow.points = {tail, tip};
      arrow.scale.x = 0.1;  // shaft diameter [m]
      arrow.scale.y = 0.25; // head diameter
      arrow.scale.z = 0.3;  // head length
      arrow.color.r = 0.0;
      arrow.color.g = 0.45;
      arrow.color.b = 0.8;
      arrow.color.a = 1.0;
    }
    array.markers.push_back(arrow);
    markers_pub_.publish(array);

    const cv::Mat img = clothwind::sensors::DrawWindPlot(estimates_, anemometer_, t_now, plot_window_, plot_width_,
                                                         plot_height_);
    sensor_msgs::Image msg;
    msg.header = text.header;
    msg.height = img.rows;
    msg.width = img.cols;
    msg.encoding = "bgr8";
    msg.step = img.cols * 3;
    msg.data.resize(static_cast<size_t>(msg.step) * img.rows);
    for (int y = 0; y < img.rows; ++y) std::copy(img.ptr<uint8_t>(y), img.ptr<uint8_t>(y) + msg.step,
                                                 msg.data.begin() + static_cast<size_t>(y) * msg.step);
    plot_pub_.publish(msg);
  }

  // Latched identity transform fixed_frame_ -> frame (stamp 0: valid at all times).
  void PublishFixedFrame(const std::string& frame) {
    tf2_msgs::TFMessage tf;
    geometry_msgs::TransformStamped t;
    t.header.frame_id = fixed_frame_;
    t.child_frame_id = frame;
    t.transform.rotation.w = 1.0;
    tf.transforms.push_back(t);
    tf_pub_.publish(tf);
    tf_child_ = frame;
  }

  double mean_window_ = 60.0, plot_window_ = 180.0;
  int plot_width_ = 640, plot_height_ = 320;
  std::string frame_id_param_, fixed_frame_, tf_child_;
  WindHistory estimates_, anemometer_;
  clothwind::WindEstimate last_estimate_;
  clothwind::WindMeasurement last_wind_;
  bool have_estimate_ = false, have_wind_ = false;
  ros::Time latest_stamp_;
  ros::Publisher markers_pub_, plot_pub_, tf_pub_;
  ros::Subscriber estimate_sub_, wind_sub_;
  ros::Timer timer_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "wind_display");
  WindDisplayNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  ros::spin();
  return 0;
}
