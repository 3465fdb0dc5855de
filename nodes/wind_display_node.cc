// wind_display_node: turns the latest wind estimate and anemometer readings into things rviz
// shows (rviz cannot plot custom scalar messages), for launch/monitor.launch:
//   monitor/wind_markers (visualization_msgs/MarkerArray): a view-facing text, two lines
//     "estimate 3.4 ± 0.3 m/s, 60 s mean 3.6" / "anemometer 3.2 m/s (60 s mean)", and an arrow along the
//     anemometer's latest air velocity (REP 103: where the wind blows TO), 1 m per m/s, in the
//     anemometer's frame (header.frame_id of anemometer/wind, so rviz needs no transform when its
//     fixed frame is that frame);
//   monitor/wind_plot (sensor_msgs/Image, bgr8): estimate (with ±std band) vs anemometer over the
//     last ~plot_window seconds, in the anemometer's frame, stamped with the display's now (ROS
//     time, never before the newest input's stamp).
// Inputs: wind/estimate (clothwind/WindEstimate), anemometer/wind (clothwind/WindMeasurement).
// Parameters: ~mean_window [s] (60), ~plot_window [s] (180), ~plot_width/~plot_height [px]
// (640x320), ~rate [Hz] (2), ~frame_id ("" = the anemometer's frame, else this one),
// ~fixed_frame ("" = none): when set, a latched /tf_static places the display frame at this
// frame with the identity transform, from the start (and again when the display frame changes),
// so rviz has a fixed frame without a robot's TF tree before any data comes (the
// monitor does not know where the anemometer is; leave it empty when a real TF tree exists).
// ~stale_after [s] (10): an estimate older than this (by ROS time, or received longer ago than
// this by the wall clock: a bag that ended stops /clock) is shown as "--", and the anemometer's
// mean and arrow go when no reading is left in ~mean_window (either clock); the plot scrolls with
// the clock while inputs pause. The display frame is ~frame_id, else the frame of the first
// valid reading with a velocity (else of the first valid one): readings in another frame (MWD's
// earth frame beside MWV's instrument frame) add their speeds and no arrow, so neither the arrow's
// convention nor /tf_static flips. /diagnostics says how old each input is. Messages stamped 0
// are dropped (counted): they would stamp the displays 0 and empty the plot; so are messages
// stamped more than ~max_future [s] (5) ahead of a running clock. When the clock or the inputs go
// back by more than 5 s (a replay restarted), everything shown is dropped and the display starts
// afresh (counted in diagnostics).
// Drawing and averaging are the ROS-free sensors/wind_plot.
#include <cmath>
#include <limits>
#include <string>

#include <algorithm>
#include <stdexcept>

#include <clothwind/WindEstimate.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <clothwind/WindMeasurement.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <visualization_msgs/MarkerArray.h>

#include "sensors/wind_direction_frame.h"
#include "sensors/wind_plot.h"
#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_throttle.h"

namespace {

using clothwind::sensors::WindHistory;
using clothwind::sensors::WindSample;

class WindDisplayNode {
 public:
  WindDisplayNode(ros::NodeHandle nh, clothwind::ros_bridge::StrictParams& params)
      : estimates_(1.0), anemometer_(1.0) {
    mean_window_ = params.Get("mean_window", 60.0);
    plot_window_ = params.Get("plot_window", 180.0);
    plot_width_ = params.Get("plot_width", 640);
    plot_height_ = params.Get("plot_height", 320);
    frame_id_param_ = params.Get("frame_id", "");
    fixed_frame_ = params.Get("fixed_frame", "");
    const double rate = params.Get("rate", 2.0);
    stale_after_ = params.Get("stale_after", 10.0);
    max_future_ = params.Get("max_future", 5.0);
    auto positive = [](double v) { return std::isfinite(v) && v > 0; };
    if (!positive(mean_window_) || !positive(plot_window_) || !positive(rate) || !positive(stale_after_) ||
        !positive(max_future_) ||
        plot_width_ < 160 || plot_height_ < 120 || plot_width_ > 4096 || plot_height_ > 4096) {
      char what[320];
      std::snprintf(what, sizeof what,
                    "~mean_window, ~plot_window, ~rate, ~stale_after and ~max_future must be finite and > 0, ~plot_width x "
                    "~plot_height from 160x120 to 4096x4096 (got %g, %g, %g, %g, %g, %dx%d)",
                    mean_window_, plot_window_, rate, stale_after_, max_future_, plot_width_, plot_height_);
      throw std::invalid_argument(what);
    }
    span_ = std::max(mean_window_, plot_window_) + 10.0;
    estimates_ = WindHistory(span_);
    anemometer_ = WindHistory(span_);
    markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("monitor/wind_markers", 1, true);
    plot_pub_ = nh.advertise<sensor_msgs::Image>("monitor/wind_plot", 1, true);
    frame_gate_ = clothwind::sensors::WindDirectionFrameGate(frame_id_param_);
    // The fixed frame from the start, at the frame the displays will use (~frame_id, else
    // "anemometer" until a reading names its own; Draw moves it then): published only once data
    // had come, rviz showed "Fixed Frame [monitor] does not exist" until then.
    if (!fixed_frame_.empty()) {
      tf_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, true);
      if (FrameId() != fixed_frame_) PublishFixedFrame(FrameId());
    }
    estimate_sub_ = nh.subscribe("wind/estimate", 10, &WindDisplayNode::OnEstimate, this);
    wind_sub_ = nh.subscribe("anemometer/wind", 50, &WindDisplayNode::OnWind, this);
    // Redraw on a timer, not per message: the plot scrolls with time even when inputs pause. A wall
    // timer: a ROS timer stops with /clock when a bag ends, and the last estimate stayed "live".
    timer_ = nh.createWallTimer(ros::WallDuration(1.0 / rate), &WindDisplayNode::Publish, this);
    updater_.setHardwareID("wind_display");
    updater_.add("wind display", this, &WindDisplayNode::Diagnose);
    diagnostics_timer_ = nh.createWallTimer(ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) {
      updater_.force_update();  // wall time: a paused bag must not stop them
    });
  }

 private:
  void OnEstimate(const clothwind::WindEstimate::ConstPtr& msg) {
    if (!Plausible(msg->speed)) return;
    if (!AdmitStamp(msg->header.stamp, &newest_estimate_)) return;
    estimates_.Add({msg->header.stamp.toSec(), msg->speed, msg->speed_std});
    last_estimate_ = *msg;
    last_estimate_wall_ = ros::WallTime::now();
    have_estimate_ = true;
  }

  void OnWind(const clothwind::WindMeasurement::ConstPtr& msg) {
    if (!msg->valid) return;
    if (!Plausible(msg->speed)) return;
    if (!AdmitStamp(msg->header.stamp, &newest_wind_)) return;
    anemometer_.Add({msg->header.stamp.toSec(), msg->speed, 0.0});
    last_wind_ = *msg;
    last_wind_wall_ = ros::WallTime::now();
    if (!have_wind_) first_wind_frame_ = msg->header.frame_id;
    have_wind_ = true;
    // The arrow only from readings in the display frame (a speed has no frame, a vector has).
    const bool has_vector = std::isfinite(msg->velocity.x) && std::isfinite(msg->velocity.y);
    if (frame_gate_.Admit(msg->header.frame_id, has_vector ? 0.0 : std::nan(""))) {
      if (has_vector) {
        last_vector_ = *msg;
        last_vector_wall_ = last_wind_wall_;
        have_vector_ = true;
      }
    } else {
      WALL_WARN_THROTTLE(30.0, "wind_display: reading in frame '%s' left out of the arrow, drawn in '%s' "
                        "(~frame_id)", msg->header.frame_id.c_str(), frame_gate_.frame_id().c_str());
    }
  }

  // Whether an input's stamp may be shown; keeps each input's newest stamp (the newer of the two
  // stamps the displays: bag time on replay, so rviz on sim time shows them in step with the images).
  // Refused (counted): stamp 0 (it would stamp the displays 0 and empty the plot), and a stamp more
  // than ~max_future ahead of a running clock (one reading stamped TIME_MAX made every later age
  // a Duration out of range, which killed the node; one 100 s ahead moved the display's now and
  // wiped the history). A stamp more than kRestartAfter behind the newest of the same input means
  // the replay restarted: everything shown is from the previous pass and is dropped. (Per input:
  // estimates lag the readings by a clip's span and the model's queue, which is no restart.)
  // All in double seconds: ros::Time arithmetic throws on results beyond 32 bits.
  bool AdmitStamp(const ros::Time& stamp, ros::Time* newest_of_input) {
    if (stamp.isZero()) {
      ++unstamped_;
      return false;
    }
    const double now = ros::Time::now().toSec(), t = stamp.toSec();
    if (now > 0 && t > now + max_future_) {
      ++future_stamped_;
      WALL_WARN_THROTTLE(10.0, "wind_display: input stamped %.1f s ahead of the clock dropped", t - now);
      return false;
    }
    if (t + WindHistory::kRestartAfter < newest_of_input->toSec()) Restart();
    *newest_of_input = std::max(*newest_of_input, stamp);
    return true;
  }

  // A speed an anemometer can read (0..100 m/s, as the clip labels take): others are dropped and
  // counted (1e300 filled the text with 63 digits, -50 showed as a wind, with status OK).
  bool Plausible(double speed) {
    if (std::isfinite(speed) && speed >= 0 && speed <= 100) return true;
    ++implausible_;
    return false;
  }

  // Forgets what is shown: the clock or the inputs went back (a replay restarted).
  void Restart() {
    estimates_ = WindHistory(span_);
    anemometer_ = WindHistory(span_);
    have_estimate_ = have_wind_ = have_vector_ = false;
    newest_estimate_ = newest_wind_ = ros::Time();
    ++restarts_;
  }

  // The display's "now": ROS time (so the plot scrolls and old values age while inputs pause), but
  // never before the newest input (latency) and the newest input while time has not started or
  // has just gone back (a replay restarting, until its first message moves the newest stamp back).
  ros::Time DisplayNow() const {
    const ros::Time now = ros::Time::now(), latest = std::max(newest_estimate_, newest_wind_);
    if (now.isZero() || now.toSec() + WindHistory::kRestartAfter < latest.toSec()) return latest;
    return std::max(now, latest);
  }

  // Age of an input [s] at `now` (the display's); infinity when there was none.
  static double Age(bool have, const ros::Time& stamp, const ros::Time& now) {
    return have ? now.toSec() - stamp.toSec() : std::numeric_limits<double>::infinity();
  }
  // Whether an input is recent enough to show: by its stamp against the display's now, and by the
  // wall clock since it arrived (the display's now stands still when a bag has ended).
  static bool Live(bool have, const ros::Time& stamp, const ros::WallTime& arrived, const ros::Time& now,
                   double limit) {
    const double age = Age(have, stamp, now);
    // A value from the display's future (before a clock jump back was noticed) is not live either.
    return age <= limit && age >= -WindHistory::kRestartAfter && (ros::WallTime::now() - arrived).toSec() <= limit;
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    using diagnostic_msgs::DiagnosticStatus;
    const ros::Time now = DisplayNow();
    const double est_age = Age(have_estimate_, last_estimate_.header.stamp, now);
    const double wind_age = Age(have_wind_, last_wind_.header.stamp, now);
    stat.summary(DiagnosticStatus::OK, "showing estimate and anemometer");
    if (!Live(have_estimate_, last_estimate_.header.stamp, last_estimate_wall_, now, stale_after_))
      stat.mergeSummary(DiagnosticStatus::WARN, have_estimate_ ? "estimate stale (shown as --)" : "no estimate yet");
    if (!Live(have_wind_, last_wind_.header.stamp, last_wind_wall_, now, mean_window_))
      stat.mergeSummary(DiagnosticStatus::WARN,
                        have_wind_ ? "no anemometer reading in the mean window" : "no anemometer reading yet");
    if (unstamped_ > 0) stat.mergeSummary(DiagnosticStatus::WARN, "messages stamped 0 dropped");
    if (future_stamped_ > 0) stat.mergeSummary(DiagnosticStatus::WARN, "messages stamped in the future dropped");
    if (implausible_ > 0) stat.mergeSummary(DiagnosticStatus::WARN, "speeds outside 0..100 m/s dropped");
    if (!publish_error_.empty()) stat.mergeSummary(DiagnosticStatus::ERROR, "cannot draw: " + publish_error_);
    stat.addf("estimate age [s]", "%.1f", est_age);
    stat.addf("anemometer age [s]", "%.1f", wind_age);
    stat.add("messages stamped 0 dropped", unstamped_);
    stat.add("messages stamped more than ~max_future ahead dropped", future_stamped_);
    stat.add("restarts (clock or inputs went back)", restarts_);
    stat.add("speeds outside 0..100 m/s dropped", implausible_);
    stat.add("frame", FrameId());
    stat.add("readings in another frame (no arrow)", frame_gate_.rejected());
    stat.addf("estimate received [s ago, wall]", "%.1f",
              have_estimate_ ? (ros::WallTime::now() - last_estimate_wall_).toSec() : -1.0);
  }

  // The display frame: ~frame_id, else the first valid reading's with a velocity (the arrow's),
  // else the first valid reading's (a speed-only instrument's text), else "anemometer".
  std::string FrameId() const {
    if (!frame_gate_.frame_id().empty()) return frame_gate_.frame_id();
    if (!first_wind_frame_.empty()) return first_wind_frame_;
    return "anemometer";
  }

  void Publish(const ros::WallTimerEvent& event) {
    // The clock went back (a replay restarted) before any input of the new pass came: what is
    // shown is the previous pass's.
    const double clock = ros::Time::now().toSec();
    if (clock > 0 && last_clock_ > 0 && clock + WindHistory::kRestartAfter < last_clock_) Restart();
    if (clock > 0) last_clock_ = clock;
    // A drawing failure is said in diagnostics and the next tick tries again; it must not end
    // the node (an exception out of a timer callback leaves ros::spin and main).
    try {
      Draw();
      publish_error_.clear();
    } catch (const std::exception& e) {
      publish_error_ = e.what();
      WALL_ERROR_THROTTLE(10.0, "wind_display: %s", e.what());
    }
  }

  void Draw() {
    if (!have_estimate_ && !have_wind_) return;  // nothing to show yet
    const std::string frame = FrameId();
    if (!fixed_frame_.empty() && frame != tf_child_ && frame != fixed_frame_) PublishFixedFrame(frame);
    const ros::Time stamp = DisplayNow();
    const double t_now = stamp.toSec();
    // A value older than it should be is not shown as if live (sdn_node died, the bag ended).
    const bool est_live = Live(have_estimate_, last_estimate_.header.stamp, last_estimate_wall_, stamp, stale_after_);
    const bool wind_live = Live(have_wind_, last_wind_.header.stamp, last_wind_wall_, stamp, mean_window_);
    const bool vector_live = Live(have_vector_, last_vector_.header.stamp, last_vector_wall_, stamp, mean_window_);
    const double mean = wind_live ? anemometer_.Mean(t_now, mean_window_) : std::nan("");
    const double est = est_live ? last_estimate_.speed : std::nan("");
    const double est_std = est_live ? last_estimate_.speed_std : std::nan("");

    visualization_msgs::MarkerArray array;
    visualization_msgs::Marker text;
    text.header.stamp = stamp;
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
    const double est_mean = est_live ? estimates_.Mean(t_now, mean_window_) : std::nan("");
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
    const bool has_vector = vector_live;
    arrow.action = has_vector ? visualization_msgs::Marker::ADD : visualization_msgs::Marker::DELETE;
    if (has_vector) {
      geometry_msgs::Point tail, tip;
      tip.x = last_vector_.velocity.x;  // 1 m per m/s
      tip.y = last_vector_.velocity.y;
      tip.z = std::isfinite(last_vector_.velocity.z) ? last_vector_.velocity.z : 0.0;
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

  double mean_window_ = 60.0, plot_window_ = 180.0, stale_after_ = 10.0, max_future_ = 5.0, span_ = 1.0;
  uint64_t unstamped_ = 0, future_stamped_ = 0, restarts_ = 0, implausible_ = 0;
  double last_clock_ = 0;          // ROS time at the last draw [s]
  ros::Time newest_estimate_, newest_wind_;  // each input's newest stamp since the last restart
  std::string publish_error_;      // why the last draw failed ("" when it did not)
  diagnostic_updater::Updater updater_;
  ros::WallTimer diagnostics_timer_;
  int plot_width_ = 640, plot_height_ = 320;
  std::string frame_id_param_, fixed_frame_, tf_child_;
  WindHistory estimates_, anemometer_;
  clothwind::WindEstimate last_estimate_;
  clothwind::WindMeasurement last_wind_, last_vector_;  // the newest valid reading; the newest with a
                                                       // vector in the display frame
  ros::WallTime last_estimate_wall_, last_wind_wall_, last_vector_wall_;  // when they arrived
  std::string first_wind_frame_;  // header.frame_id of the first valid reading
  clothwind::sensors::WindDirectionFrameGate frame_gate_;
  bool have_estimate_ = false, have_wind_ = false, have_vector_ = false;
  ros::Publisher markers_pub_, plot_pub_, tf_pub_;
  ros::Subscriber estimate_sub_, wind_sub_;
  ros::WallTimer timer_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "wind_display");
  // Held outside the try: the last NodeHandle going out of scope shuts ROS down, and the FATAL
  // naming a bad parameter was then never printed (exit 1, silent).
  ros::NodeHandle nh, pnh("~");
  clothwind::ros_bridge::StrictParams params(pnh);
  try {
    WindDisplayNode node(nh, params);
    params.Known("diagnostic_period");  // diagnostic_updater's
    params.WarnUnread("wind_display");
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("wind_display: %s", e.what());
    return 1;
  }
  return 0;
}
