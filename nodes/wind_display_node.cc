// wind_display_node: turns the latest wind estimate and anemometer readings into things rviz
// shows (rviz cannot plot custom scalar messages), for launch/monitor.launch:
//   monitor/wind_markers (visualization_msgs/MarkerArray): a view-facing text, three lines
//     "estimate 3.4 ± 0.3 m/s" / "60 s mean 3.6" / "anemometer 3.2 m/s (60 s mean)", and an arrow along
//     the anemometer's latest air velocity (REP 103: where the wind blows TO), 0.3 m per m/s up to
//     4.5 m (sensors/wind_plot.h WindArrowScale), in the
//     anemometer's frame (header.frame_id of anemometer/wind, so rviz needs no transform when its
//     fixed frame is that frame);
//   monitor/wind_plot (sensor_msgs/Image, bgr8): estimate (with ±std band) vs anemometer over the
//     last ~plot_window seconds, in the anemometer's frame, stamped with the display's now (ROS
//     time, never before the newest input's stamp).
// Inputs: wind/estimate (clothwind/WindEstimate), anemometer/wind (clothwind/WindMeasurement),
//   wind/estimate_mean (sdn_node's trailing mean: shown as the estimates' mean when it is the
//   latest estimate's, being of the network's outputs before the clamp at 0).
// Parameters: ~mean_window [s] (60), ~plot_window [s] (180), ~plot_width/~plot_height [px]
// (640x320), ~rate [Hz] (2), ~frame_id ("" = the anemometer's frame, else this one),
// ~fixed_frame ("" = none): when set, a latched /tf_static hangs this frame, the display's own,
// under the display frame with the identity transform, from the start (and again when the
// display frame changes), so rviz has a fixed frame before any data comes. The display's frame
// is the parent, never the child: a robot whose TF tree already places the anemometer's frame
// keeps it (a frame has one parent; the old direction gave it a second). Name a frame nobody
// else publishes (monitor.launch: "monitor").
// ~stale_after [s] (10): an estimate older than this (by ROS time, or received longer ago than
// this by the wall clock: a bag that ended stops /clock) is shown as "--", and the anemometer's
// mean and arrow go when no reading is left in ~mean_window (either clock); the plot scrolls with
// the clock while inputs pause. The display frame is ~frame_id, else the frame of the first
// valid reading with a velocity other than calm (0, 0, 0) (else of the first valid one): readings in another frame (MWD's
// earth frame beside MWV's instrument frame) add their speeds and no arrow, so neither the arrow's
// convention nor /tf_static flips. /diagnostics says how old each input is. Messages stamped 0
// are dropped (counted): they would stamp the displays 0 and empty the plot; so are messages
// stamped more than ~max_future [s] (5) ahead of a running clock; so are speeds or stds outside
// 0..100 m/s, and readings marked invalid; a velocity beyond 100 m/s draws no arrow. Each such drop
// is a WARN for ~drop_warn_for [s] (30) after the last one, the totals are kept as values. When
// the clock goes back by more than 5 s (a replay restarted), everything shown is dropped and the
// display starts afresh, showing "--" until the new pass's inputs come (counted in diagnostics);
// estimates of the previous pass still arriving then (sdn_node's queue) are dropped and counted as
// such, not as stamped in the future. One message more than 5 s behind the newest of its input
// while the clock has not gone back (a second publisher, a relay, a bad stamp) is dropped as
// late; a late one within 5 s joins the history but is not shown as the latest. Lazy, as
// image_pipeline's nodes: nothing is drawn while neither display has a subscriber.
// Drawing and averaging are the ROS-free sensors/wind_plot; which stamps are shown, when the display
// restarts and its now, sensors/display_clock.
#include <cmath>
#include <cstdio>
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

#include "sensors/display_clock.h"
#include "sensors/wind_direction_frame.h"
#include "sensors/wind_plot.h"
#include "common/formatted.h"
#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "ros_bridge/wall_throttle.h"

namespace {

using clothwind::sensors::WindHistory;
using clothwind::sensors::WindSample;

class WindDisplayNode {
 public:
  WindDisplayNode(ros::NodeHandle nh, clothwind::ros_bridge::StrictParams& params)
      : clock_(kInputs, 1.0, WindHistory::kRestartAfter), estimates_(1.0), anemometer_(1.0) {
    mean_window_ = params.Get("mean_window", 60.0);
    plot_window_ = params.Get("plot_window", 180.0);
    plot_width_ = params.Get("plot_width", 640);
    plot_height_ = params.Get("plot_height", 320);
    frame_id_param_ = params.Get("frame_id", "");
    fixed_frame_ = params.Get("fixed_frame", "");
    const double rate = params.Get("rate", 2.0);
    stale_after_ = params.Get("stale_after", 10.0);
    max_future_ = params.Get("max_future", 5.0);
    drop_warn_for_ = params.Get("drop_warn_for", 30.0);
    auto positive = [](double v) { return std::isfinite(v) && v > 0; };
    // ~rate's bound: 1/rate must be a WallDuration (1e-12 Hz ended the node naming no parameter).
    if (!(rate >= 1e-3 && rate <= 1000))
      throw std::invalid_argument("~rate must be from 0.001 to 1000 Hz, got " + clothwind::Formatted("%g", rate));
    if (!positive(mean_window_) || !positive(plot_window_) || !positive(rate) || !positive(stale_after_) ||
        !positive(max_future_) || !positive(drop_warn_for_) ||
        plot_width_ < 160 || plot_height_ < 120 || plot_width_ > 4096 || plot_height_ > 4096) {
      char what[320];
      std::snprintf(what, sizeof what,
                    "~mean_window, ~plot_window, ~rate, ~stale_after, ~max_future and ~drop_warn_for must be finite and > 0, "
                    "~plot_width x ~plot_height from 160x120 to 4096x4096 (got %g, %g, %g, %g, %g, %g, %dx%d)",
                    mean_window_, plot_window_, rate, stale_after_, max_future_, drop_warn_for_, plot_width_,
                    plot_height_);
      throw std::invalid_argument(what);
    }
    clock_ = clothwind::sensors::DisplayClock(kInputs, max_future_, WindHistory::kRestartAfter);
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
    mean_sub_ = nh.subscribe("wind/estimate_mean", 10, &WindDisplayNode::OnEstimateMean, this);
    wind_sub_ = nh.subscribe("anemometer/wind", 50, &WindDisplayNode::OnWind, this);
    // Redraw on a timer, not per message: the plot scrolls with time even when inputs pause. A wall
    // timer: a ROS timer stops with /clock when a bag ends, and the last estimate stayed "live".
    timer_ = nh.createSteadyTimer(ros::WallDuration(1.0 / rate), &WindDisplayNode::Publish, this);
    updater_.setHardwareID("wind_display");
    updater_.add("wind display", this, &WindDisplayNode::Diagnose);
    diagnostics_timer_ = nh.createSteadyTimer(
        ros::WallDuration(clothwind::ros_bridge::DiagnosticPeriod(updater_)), [this](const ros::SteadyTimerEvent&) {
      clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);  // wall time: a paused bag must not stop them
    });
  }

 private:
  void OnEstimate(const clothwind::WindEstimate::ConstPtr& msg) {
    // speed_std NaN means none (WindEstimate.msg); 1e300 filled the text with 300 digits.
    if (!Plausible(msg->speed) || !(std::isnan(msg->speed_std) || Plausible(msg->speed_std))) return;
    if (!AdmitStamp(msg->header.stamp, kEstimateInput)) return;
    estimates_.Add({msg->header.stamp.toSec(), msg->speed, msg->speed_std});
    // The latest by stamp, not by arrival: a late estimate joins the history only (shown as the
    // latest, it hid the newer one and aged the display).
    if (!have_estimate_ || msg->header.stamp >= last_estimate_.header.stamp) {
      last_estimate_ = *msg;
      last_estimate_wall_ = ros::SteadyTime::now();
    }
    have_estimate_ = true;
  }

  // sdn_node's trailing mean of the same estimates: of the network's outputs before the clamp at 0,
  // where the mean of the clamped estimates reads high in calm air.
  // Taken only over this display's ~mean_window (the message's mean_window): a 120 s mean was shown
  // as the "60 s mean" otherwise.
  void OnEstimateMean(const clothwind::WindEstimate::ConstPtr& msg) {
    if (!Plausible(msg->speed)) return;
    if (!(msg->mean_window > 0) || std::abs(msg->mean_window - mean_window_) > 0.5) return;
    if (!have_mean_ || msg->header.stamp >= last_mean_.header.stamp) {
      last_mean_ = *msg;
      have_mean_ = true;
    }
  }

  void OnWind(const clothwind::WindMeasurement::ConstPtr& msg) {
    if (!msg->valid) {
      Dropped(&invalid_, kInvalid);  // a sensor that only reports void readings says so
      return;
    }
    if (!Plausible(msg->speed)) return;
    if (!AdmitStamp(msg->header.stamp, kWindInput)) return;
    anemometer_.Add({msg->header.stamp.toSec(), msg->speed, 0.0});
    const bool newest = !have_wind_ || msg->header.stamp >= last_wind_.header.stamp;
    if (newest) {
      last_wind_ = *msg;
      last_wind_wall_ = ros::SteadyTime::now();
    }
    if (!have_wind_) first_wind_frame_ = msg->header.frame_id;
    have_wind_ = true;
    // The arrow only from readings in the display frame (a speed has no frame, a vector has), and
    // of a velocity an anemometer can read (1e30 drew an arrow of infinite length in rviz's floats).
    const double vz = std::isfinite(msg->velocity.z) ? msg->velocity.z : 0.0;
    bool has_vector = std::isfinite(msg->velocity.x) && std::isfinite(msg->velocity.y);
    if (has_vector && std::sqrt(msg->velocity.x * msg->velocity.x + msg->velocity.y * msg->velocity.y + vz * vz) >
                          kMaxSpeed) {
      has_vector = false;
      Dropped(&implausible_velocity_, kVelocity);
    }
    // A calm velocity (0, 0, 0) has no bearing, so it names no frame: a station whose first
    // reading was calm made its frame the display's and left every later bearing, in another
    // frame, out of the arrow. Before the display has a frame its zero arrow is drawn; after, a
    // calm reading in another frame is left out like any other (it zeroed the arrow).
    const bool bearing = has_vector && (msg->velocity.x != 0.0 || msg->velocity.y != 0.0 || vz != 0.0);
    const bool names_frame = bearing || (has_vector && !frame_gate_.frame_id().empty());
    if (frame_gate_.Admit(msg->header.frame_id, names_frame ? 0.0 : std::nan(""))) {
      if (has_vector && (!have_vector_ || msg->header.stamp >= last_vector_.header.stamp)) {
        last_vector_ = *msg;
        last_vector_wall_ = ros::SteadyTime::now();
        have_vector_ = true;
      }
    } else {
      WALL_WARN_THROTTLE(30.0, "wind_display: reading in frame '%s' left out of the arrow, drawn in '%s' "
                        "(~frame_id)", msg->header.frame_id.c_str(), frame_gate_.frame_id().c_str());
    }
  }

  // Whether an input's stamp may be shown (sensors/display_clock.h says which stamps are refused
  // and when the display restarts); the refused are counted, by cause.
  bool AdmitStamp(const ros::Time& stamp, int input) {
    bool restarted = false;
    const auto verdict = clock_.Admit(input, stamp.toNSec(), ros::Time::now().toNSec(), &restarted);
    if (restarted) ForgetShown();
    using Verdict = clothwind::sensors::DisplayClock::Verdict;
    switch (verdict) {
      case Verdict::kShow:
        return true;
      case Verdict::kUnstamped:
        Dropped(&unstamped_, kUnstamped);
        return false;
      case Verdict::kPreviousPass:
        ++previous_pass_;
        return false;
      case Verdict::kFuture:
        Dropped(&future_stamped_, kFuture);
        WALL_WARN_THROTTLE(10.0, "wind_display: input stamped %.1f s ahead of the clock dropped",
                           stamp.toSec() - ros::Time::now().toSec());
        return false;
      case Verdict::kLate:
        Dropped(&late_, kLate);
        WALL_WARN_THROTTLE(10.0, "wind_display: input stamped %.1f s behind the newest of its kind dropped",
                           ros::Time().fromNSec(clock_.Newest(input)).toSec() - stamp.toSec());
        return false;
    }
    return false;
  }

  // A speed an anemometer can read (0..100 m/s, as the clip labels take): others are dropped and
  // counted (1e300 filled the text with 63 digits, -50 showed as a wind, with status OK).
  static constexpr double kMaxSpeed = 100.0;  // [m/s]
  bool Plausible(double speed) {
    if (std::isfinite(speed) && speed >= 0 && speed <= kMaxSpeed) return true;
    Dropped(&implausible_, kImplausible);
    return false;
  }

  // Why messages are dropped; each cause is a WARN for ~drop_warn_for after its last drop.
  enum DropCause { kUnstamped, kFuture, kImplausible, kLate, kInvalid, kVelocity, kDropCauses };
  static constexpr const char* kDropWarnings[kDropCauses] = {
      "messages stamped 0 dropped",          "messages stamped in the future dropped",
      "speeds or stds outside 0..100 m/s dropped", "messages more than 5 s late dropped",
      "readings marked invalid dropped",     "velocities beyond 100 m/s (no arrow)"};

  // Counts a dropped message and when it was dropped (wall time: a paused bag must not hold it).
  void Dropped(uint64_t* counter, DropCause cause) {
    ++*counter;
    last_drop_wall_[cause] = ros::SteadyTime::now();
  }

  // Forgets what is shown: the clock or the inputs went back (a replay restarted).
  void ForgetShown() {
    estimates_ = WindHistory(span_);
    anemometer_ = WindHistory(span_);
    have_estimate_ = have_wind_ = have_vector_ = have_mean_ = false;
  }

  ros::Time DisplayNow() const { return ros::Time().fromNSec(clock_.DisplayNow(ros::Time::now().toNSec())); }

  // Age of an input [s] at `now` (the display's); infinity when there was none.
  static double Age(bool have, const ros::Time& stamp, const ros::Time& now) {
    return have ? now.toSec() - stamp.toSec() : std::numeric_limits<double>::infinity();
  }
  // Whether an input is recent enough to show: by its stamp against the display's now, and by the
  // wall clock since it arrived (the display's now stands still when a bag has ended).
  static bool Live(bool have, const ros::Time& stamp, const ros::SteadyTime& arrived, const ros::Time& now,
                   double limit) {
    const double age = Age(have, stamp, now);
    // A value from the display's future (before a clock jump back was noticed) is not live either.
    return age <= limit && age >= -WindHistory::kRestartAfter && (ros::SteadyTime::now() - arrived).toSec() <= limit;
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
    // Each cause of drops is a WARN for drop_warn_for_ after its own last drop (time to be read),
    // then no longer: a total since start kept one bad message a WARN for good.
    const ros::SteadyTime wall = ros::SteadyTime::now();
    for (int c = 0; c < kDropCauses; ++c) {
      if (!last_drop_wall_[c].isZero() && (wall - last_drop_wall_[c]).toSec() < drop_warn_for_)
        stat.mergeSummary(DiagnosticStatus::WARN, kDropWarnings[c]);
    }
    if (!publish_error_.empty()) stat.mergeSummary(DiagnosticStatus::ERROR, "cannot draw: " + publish_error_);
    stat.addf("estimate age [s]", "%.1f", est_age);
    stat.addf("anemometer age [s]", "%.1f", wind_age);
    stat.add("messages stamped 0 dropped", unstamped_);
    stat.add("messages stamped more than ~max_future ahead dropped", future_stamped_);
    stat.add("restarts (clock or inputs went back)", clock_.Restarts());  // key kept for the tests and tools reading it
    stat.add("speeds or stds outside 0..100 m/s dropped", implausible_);
    stat.add("messages more than 5 s behind the newest of their input dropped (clock steady)", late_);
    stat.add("messages of the previous pass dropped (after the clock went back)", previous_pass_);
    stat.add("readings marked invalid dropped", invalid_);
    stat.add("velocities beyond 100 m/s (no arrow)", implausible_velocity_);
    stat.add("subscribers (markers, plot)", std::to_string(markers_pub_.getNumSubscribers()) + ", " +
                                                std::to_string(plot_pub_.getNumSubscribers()));
    stat.add("displays drawn", drawn_);
    stat.add("frame", FrameId());
    stat.add("readings in another frame (no arrow)", frame_gate_.rejected());
    stat.addf("estimate received [s ago, wall]", "%.1f",
              have_estimate_ ? (ros::SteadyTime::now() - last_estimate_wall_).toSec() : -1.0);
  }

  // The display frame: ~frame_id, else the first valid reading's with a bearing (the arrow's),
  // else the first valid reading's (a speed-only instrument's text), else "anemometer".
  std::string FrameId() const {
    if (!frame_gate_.frame_id().empty()) return frame_gate_.frame_id();
    if (!first_wind_frame_.empty()) return first_wind_frame_;
    return "anemometer";
  }

  void Publish(const ros::SteadyTimerEvent& event) {
    // The clock went back (a replay restarted) before any input of the new pass came: what is
    // shown is the previous pass's.
    if (clock_.CheckClock(ros::Time::now().toNSec())) ForgetShown();
    const std::string frame = FrameId();
    if (!fixed_frame_.empty() && frame != tf_parent_ && frame != fixed_frame_) PublishFixedFrame(frame);
    // Lazy: the plot is a 640x320 image drawn at ~rate; nobody looking, nothing drawn. A new
    // subscriber gets the latched last one at once and a fresh one at the next tick.
    if (markers_pub_.getNumSubscribers() == 0 && plot_pub_.getNumSubscribers() == 0) return;
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
    // Nothing to show yet. After a restart, though, the displays are drawn empty ("--", no arrow,
    // no lines): they are latched and the previous pass's values stayed on screen until the new
    // pass's first input (48 s for a Fine Offset station).
    if (!have_estimate_ && !have_wind_ && drawn_ == 0) return;
    const std::string frame = FrameId();
    const ros::Time stamp = DisplayNow();
    if (stamp.isZero()) return;  // neither a clock nor an input to stamp it with
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
    text.scale.z = 0.45;  // [m] letter height: three lines within the view's ±5 m at 30 px/m
    text.color.r = text.color.g = text.color.b = 1.0;
    text.color.a = 1.0;
    // sdn_node's own mean when it is of the latest estimate (its window is ~mean_window too under
    // monitor.launch); else the mean of the estimates received.
    const double est_mean = !est_live ? std::nan("")
                            : have_mean_ && last_mean_.header.stamp == last_estimate_.header.stamp
                                ? last_mean_.speed
                                : estimates_.Mean(t_now, mean_window_);
    // What each mean spans: sdn_node's mean from its clips' first start to its last end.
    const bool own_mean = est_live && have_mean_ && last_mean_.header.stamp == last_estimate_.header.stamp;
    const double est_span = own_mean ? (last_mean_.clip_end - last_mean_.clip_start).toSec()
                                     : estimates_.Span(t_now, mean_window_);
    text.text = clothwind::sensors::WindSummaryText(est, est_std, mean, mean_window_, est_mean,
                                                    anemometer_.Span(t_now, mean_window_), est_span);
    // Three lines: the 3-D view is narrow beside the images (one line of 0.6 m letters lost its
    // ends past 10 m/s: "stimate 12.6 ± 1.3 m/s, 60 s mean 12.(6)").
    const size_t bar = text.text.find(" | ");
    if (bar != std::string::npos) text.text.replace(bar, 3, "\n");
    const size_t comma = text.text.find(", ");
    if (comma != std::string::npos && comma < text.text.find('\n')) text.text.replace(comma, 2, "\n");
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
      const double vz = std::isfinite(last_vector_.velocity.z) ? last_vector_.velocity.z : 0.0;
      const double scale = clothwind::sensors::WindArrowScale(last_vector_.velocity.x, last_vector_.velocity.y, vz);
      tip.x = scale * last_vector_.velocity.x;
      tip.y = scale * last_vector_.velocity.y;
      tip.z = scale * vz;
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
    ++drawn_;
  }

  // Latched identity transform frame -> fixed_frame_ (stamp 0: valid at all times). The display's
  // own frame is the child, so no frame of a robot's tree gets a second parent.
  void PublishFixedFrame(const std::string& frame) {
    tf2_msgs::TFMessage tf;
    geometry_msgs::TransformStamped t;
    t.header.frame_id = frame;
    t.child_frame_id = fixed_frame_;
    t.transform.rotation.w = 1.0;
    tf.transforms.push_back(t);
    tf_pub_.publish(tf);
    tf_parent_ = frame;
  }

  double mean_window_ = 60.0, plot_window_ = 180.0, stale_after_ = 10.0, max_future_ = 5.0, span_ = 1.0;
  double drop_warn_for_ = 30.0;
  uint64_t unstamped_ = 0, future_stamped_ = 0, implausible_ = 0, late_ = 0, previous_pass_ = 0,
           invalid_ = 0, implausible_velocity_ = 0, drawn_ = 0;
  ros::SteadyTime last_drop_wall_[kDropCauses];  // when each cause last dropped a message (zero: never)
  enum Input { kEstimateInput, kWindInput, kInputs };
  clothwind::sensors::DisplayClock clock_;  // each input's newest stamp, restarts, the display's now
  std::string publish_error_;      // why the last draw failed ("" when it did not)
  diagnostic_updater::Updater updater_;
  ros::SteadyTimer diagnostics_timer_;
  int plot_width_ = 640, plot_height_ = 320;
  std::string frame_id_param_, fixed_frame_, tf_parent_;
  WindHistory estimates_, anemometer_;
  clothwind::WindEstimate last_estimate_;
  clothwind::WindMeasurement last_wind_, last_vector_;  // the newest valid reading; the newest with a
                                                       // vector in the display frame
  ros::SteadyTime last_estimate_wall_, last_wind_wall_, last_vector_wall_;  // when they arrived
  std::string first_wind_frame_;  // header.frame_id of the first valid reading
  clothwind::sensors::WindDirectionFrameGate frame_gate_;
  bool have_estimate_ = false, have_wind_ = false, have_vector_ = false, have_mean_ = false;
  clothwind::WindEstimate last_mean_;  // sdn_node's latest trailing mean
  ros::Publisher markers_pub_, plot_pub_, tf_pub_;
  ros::Subscriber estimate_sub_, mean_sub_, wind_sub_;
  ros::SteadyTimer timer_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "wind_display");
  // Held outside the try: the last NodeHandle going out of scope shuts ROS down, and the FATAL
  // naming a bad parameter was then never printed (exit 1, silent).
  ros::NodeHandle nh, pnh("~");
  clothwind::ros_bridge::StrictParams params(pnh);
  try {
    clothwind::ros_bridge::CheckDiagnosticPeriod(params);  // before the node's diagnostic_updater reads it
    WindDisplayNode node(nh, params);
    params.WarnUnread("wind_display");
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("wind_display: %s", e.what());
    return 1;
  }
  return 0;
}
