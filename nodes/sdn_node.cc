// sdn_node: estimates the wind speed of every clip (clothwind/Clip on `clips`) with a trained
// wind network (SDN or baseline, src/learn/) and publishes
//   wind/estimate   clothwind/WindEstimate (speed, its std, clip stamps, anemometer reference,
//                   latency, model name)
//   wind/estimate_mean  clothwind/WindEstimate: the trailing mean of the estimates over
//                   ~mean_window seconds of clip time (sensors/trailing_mean.h), published with
//                   each estimate: the figure to hold against the anemometer's minute mean
//   sdn/power       bgr8 Image: log power of each pixel's strongest spectral peak (inferno),
//   sdn/frequency   bgr8 Image: its frequency, 0 .. Nyquist (jet); both for rviz, computed only
//                   while someone subscribes, SDN models only.
// Parameters: ~model (model.pt of a training run; model.json beside it), ~threads (2),
// ~device (cpu | cuda | auto), ~queue_size (2 clips; older ones are dropped when the node lags),
// ~mean_window (60 s, the field protocol's label window), ~flag_flies (right | left | auto | wind;
// unset: auto for a model trained without flips, which knows only flags flying right as FlagSim's
// do, right, as filmed, for one trained with them; learn/fly_direction.h). wind: each clip's way
// from its anemometer direction (wind_direction_mean) and the camera's pose: its optical frame (the
// clip's frame_id) looked up in tf2 in the direction's frame, the latest transform, so a camera
// upside down or pitched is read right (learn::EquivalentCameraHeading); or, when set,
// ~camera_heading (a level camera's optical axis in the anemometer's frame [rad];
// ~camera_heading_frame names that frame, and a clip whose direction is in another is not used).
// A wind within ~end_on_angle (20 deg) of the axis, or no pose, keeps the way last known. auto asks ~fly_judge (a train-fly-judge file; unset: fly_judge.pt
// beside the model when there is one, as models/ ships it, else the clip's motion cues).
// Clips may be mono8 or bgr8; a model trained with --colour needs bgr8 (clip_buffer ~colour) and
// reports a grey clip as an ERROR naming that parameter.
// Diagnostics (published every wall second, so a paused or restarted bag does not stall them):
// model, device, latency and rate, the flag's way and the clips turned round, clips missing from
// the sequence. A malformed clip (wrong encoding, size, stamps, or a frame rate other than the
// model's) is an ERROR, not a crash, until a good clip is estimated; a failure of the model itself
// is an ERROR of its own. A model that cannot be loaded is retried every 2 s (ERROR until it
// loads). No clip for 10 s after the first is a WARN, and so are clips missing from the sequence
// in the last 30 s (the queue dropping clips the model is too slow for, or losses upstream). A model trained without flips left on
// ~flag_flies auto with no fly judge (the motion cues misjudge ~9 % of clips) is a WARN, as is a
// fly judge that cannot load (~fly_judge, or the one beside the model) and a parameter out of its
// range (named, and its default used). A parameter of the wrong type (ros_bridge/strict_param.h)
// ends the node at start with a FATAL naming it.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include <Eigen/Geometry>
#include <diagnostic_updater/diagnostic_updater.h>
#include <image_transport/image_transport.h>
#include <opencv2/imgproc.hpp>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <clothwind/Clip.h>
#include <clothwind/WindEstimate.h>

#include "common/formatted.h"
#include "learn/camera_heading.h"
#include "learn/flag_flies_settings.h"
#include "learn/predictor.h"
#include "ros_bridge/sdn_conversions.h"
#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "ros_bridge/wall_throttle.h"
#include "sensors/sequence_gaps.h"
#include "sensors/trailing_mean.h"

namespace {

class SdnNode {
 public:
  // Throws ParamError for a parameter of the wrong type (main ends on it); one out of its range is
  // logged as an error, a WARN in diagnostics, and its default is used.
  SdnNode(ros::NodeHandle& nh, clothwind::ros_bridge::StrictParams& params)
      : transport_(nh), trailing_(MeanWindow(params)) {
    model_path_ = clothwind::ros_bridge::AbsolutePathParam("sdn_node: ~model", params.Get("model", ""));
    threads_ = params.Get("threads", 2);
    if (threads_ < 1) threads_ = ParameterError("~threads must be >= 1, got " + std::to_string(threads_), 2);
    device_ = params.Get("device", "cpu");
    if (device_ != "cpu" && device_ != "cuda" && device_ != "auto") {
      ParameterError("~device must be cpu, cuda or auto, got \"" + device_ + "\"", 0);
      device_ = "cpu";
    }
    int queue_size = params.Get("queue_size", 2);
    if (queue_size < 1) queue_size = ParameterError("~queue_size must be >= 1 clip, got " + std::to_string(queue_size), 2);
    fly_judge_path_ = clothwind::ros_bridge::AbsolutePathParam("sdn_node: ~fly_judge", params.Get("fly_judge", ""));
    if (!mean_window_error_.empty()) parameter_errors_.push_back(mean_window_error_);
    ReadFlagFlies(params);
    estimate_pub_ = nh.advertise<clothwind::WindEstimate>("wind/estimate", 10);
    mean_pub_ = nh.advertise<clothwind::WindEstimate>("wind/estimate_mean", 10);
    power_pub_ = transport_.advertise("sdn/power", 1);
    frequency_pub_ = transport_.advertise("sdn/frequency", 1);
    updater_.setHardwareID("sdn:" + model_path_);
    updater_.add("sdn", this, &SdnNode::Diagnose);
    // force_update: Updater::update() waits for ROS time, which stands still while a bag is
    // paused and jumps back when it restarts.
    diag_timer_ =
        nh.createSteadyTimer(ros::WallDuration(clothwind::ros_bridge::DiagnosticPeriod(updater_)),
                             [this](const ros::SteadyTimerEvent&) {
                               clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);
                             });
    // Subscribed before the model loads (libtorch, the weights and the warm-up take seconds):
    // clips that come meanwhile wait in the queue, as callbacks run only once spin() starts, rather
    // than going to no subscriber at all (a replay starts as soon as the bag's topics have theirs).
    queue_size_ = queue_size;
    clip_sub_ = nh.subscribe("clips", queue_size, &SdnNode::OnClip, this);
    TryLoad();
    if (!predictor_) {
      load_timer_ = nh.createSteadyTimer(ros::WallDuration(2.0), [this](const ros::SteadyTimerEvent&) {
        if (!predictor_) TryLoad();
      });
    }
  }

 private:
  // A parameter out of its range: logged, kept for the diagnostics, and its default used.
  int ParameterError(const std::string& what, int fallback) {
    ROS_ERROR("sdn_node: %s; using the default", what.c_str());
    parameter_errors_.push_back(what);
    return fallback;
  }

  // Before the members: the trailing mean is built with it.
  static double MeanWindow(clothwind::ros_bridge::StrictParams& params) {
    double window = params.Get("mean_window", 60.0);
    if (!(window > 0) || !std::isfinite(window)) {
      mean_window_error_ = "~mean_window must be a finite number of seconds > 0, got " + std::to_string(window);
      ROS_ERROR("sdn_node: %s; using 60 s", mean_window_error_.c_str());
      window = 60.0;
    }
    return window;
  }

  // ~flag_flies and, for wind, ~camera_heading and ~end_on_angle, checked once at start
  // (learn/flag_flies_settings.h): a bad value is an ERROR and leaves the model's default.
  void ReadFlagFlies(clothwind::ros_bridge::StrictParams& params) {
    const std::string name = params.Get("flag_flies", "");
    const double heading = params.Get("camera_heading", std::numeric_limits<double>::quiet_NaN());
    camera_heading_frame_ = params.Get("camera_heading_frame", "");
    const clothwind::learn::FlagFliesSettings s = clothwind::learn::ReadFlagFliesSettings(
        name, params.Has("camera_heading") ? std::optional<double>(heading) : std::nullopt, camera_heading_frame_,
        params.Get("end_on_angle", 20.0));
    for (const std::string& error : s.errors) ParameterError(error, 0);
    told_flag_flies_ = s.told;
    follow_wind_ = s.follow_wind;
    pose_from_tf_ = s.pose_from_tf;
    camera_heading_ = s.camera_heading;
    end_on_ = s.end_on;
    if (pose_from_tf_) {
      tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
      tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_);
    }
  }

  void TryLoad() {
    try {
      if (model_path_.empty()) throw std::runtime_error("parameter ~model is not set");
      auto predictor = std::make_unique<clothwind::learn::Predictor>(model_path_, threads_, device_);
      // Warm-up: the first forward pass allocates and picks kernels; keep that out of the
      // first clip's latency.
      const auto& c = predictor->config();
      std::vector<cv::Mat> frames;
      for (int i = 0; i < c.frames; ++i) {
        frames.emplace_back(c.input_size, c.input_size, clothwind::learn::FrameType(c.colour), cv::Scalar::all(i % 7));
      }
      const auto t0 = std::chrono::steady_clock::now();
      predictor->PredictFrames(frames);
      const double warm = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (follow_wind_) {
        predictor->set_flag_flies(clothwind::learn::FlagFlies::kRight);  // until the wind says
      } else if (told_flag_flies_) {
        predictor->set_flag_flies(*told_flag_flies_);
      }
      LoadFlyJudge(*predictor);
      // A ~fly_judge is asked only under auto: beside right, left or wind it loads and is never
      // asked, which a launch file's author, who likely meant auto, would not see otherwise.
      if (!fly_judge_path_.empty() && (follow_wind_ || predictor->flag_flies() != clothwind::learn::FlagFlies::kAuto)) {
        ROS_WARN("sdn_node: ~fly_judge is set but ~flag_flies is %s, not auto: the judge is not asked",
                 follow_wind_ ? "wind" : clothwind::learn::FlagFliesName(predictor->flag_flies()).c_str());
      }
      model_name_ = c.Name() + " (" + model_path_ + ")";
      ROS_INFO("sdn_node: model %s on %s, %d threads, warm-up %.0f ms, flag flies %s", model_name_.c_str(),
               predictor->device().c_str(), threads_, 1e3 * warm,
               clothwind::learn::FlagFliesName(predictor->flag_flies()).c_str());
      predictor_ = std::move(predictor);
      loaded_wall_ = ros::SteadyTime::now().toSec();
      load_error_.clear();
    } catch (const std::exception& e) {
      if (load_error_ != e.what()) ROS_ERROR("sdn_node: cannot load the model: %s (retrying)", e.what());
      load_error_ = e.what();
    }
    clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);
  }

  // ~fly_judge, when set, replaces the judge beside the model; one that cannot load is a WARN and
  // leaves the one beside the model (or the motion cues): estimates go on either way.
  void LoadFlyJudge(clothwind::learn::Predictor& predictor) {
    judge_error_.clear();
    if (fly_judge_path_.empty()) return;
    try {
      predictor.LoadFlyJudge(fly_judge_path_);
    } catch (const std::exception& e) {
      judge_error_ = e.what();
      ROS_ERROR("sdn_node: cannot load ~fly_judge: %s", e.what());
    }
  }

  void OnClip(const clothwind::Clip::ConstPtr& clip) {
    const auto received = std::chrono::steady_clock::now();
    if (!predictor_) {
      ++dropped_;
      return;
    }
    try {
      // A colour model reads Y, Cr and Cb from bgr8 clips; a grey one the grey of either kind.
      std::vector<cv::Mat> camera_frames;
      try {
        camera_frames = clothwind::ros_bridge::ClipFrames(*clip);
        clothwind::ros_bridge::CheckClipFrameRate(*clip, predictor_->config().frame_rate);
      } catch (const std::invalid_argument& e) {
        sequence_gaps_.Malformed(clip->sequence);
        throw MalformedClip(e.what());
      }
      sequence_gaps_.Good(clip->sequence, ros::SteadyTime::now().toSec());
      if (follow_wind_ && pose_from_tf_) {  // a clip that passed the checks only
        // Looked up for a clip without a direction too, so the diagnostics follow the pose.
        FollowTheWind(clip->wind_direction_mean, CameraHeadingFromTf(*clip));
        if (!pose_error_.empty()) WALL_WARN_THROTTLE(30.0, "sdn_node: %s; the way the flag flies is kept as last known",
                                                     pose_error_.c_str());
      } else if (follow_wind_) {
        // ~camera_heading is an angle in one frame: a direction in another says nothing of the way.
        const bool same_frame = camera_heading_frame_.empty() || clip->wind_direction_frame_id == camera_heading_frame_;
        if (!same_frame) {
          last_wind_frame_ = clip->wind_direction_frame_id;
          WALL_WARN_THROTTLE(30.0, "sdn_node: the clips' wind direction is in frame '%s', ~camera_heading in '%s': "
                            "the way the flag flies is kept as last known",
                            clip->wind_direction_frame_id.c_str(), camera_heading_frame_.c_str());
        }
        FollowTheWind(same_frame ? clip->wind_direction_mean : std::numeric_limits<double>::quiet_NaN(),
                      camera_heading_);
      }
      const std::vector<cv::Mat> frames =
          clothwind::learn::CameraFramesForModel(camera_frames, predictor_->config().colour);
      const bool want_maps = power_pub_.getNumSubscribers() > 0 || frequency_pub_.getNumSubscribers() > 0;
      clothwind::learn::PeakMaps maps;
      const clothwind::learn::Prediction p = predictor_->PredictFrames(frames, want_maps ? &maps : nullptr);
      // No motion to read (a frozen camera), or no scene (a covered lens, darkness: its noise moves,
      // and the network reads wind into it): the network's answer looks like a measurement, std
      // included, and is not one. Said, not published.
      if (p.no_motion || p.no_scene) {
        ++(p.no_motion ? no_motion_ : no_scene_);
        const bool first = still_clip_.empty();
        const auto sequence = static_cast<unsigned long long>(clip->sequence);
        still_clip_ =
            p.no_motion
                ? clothwind::Formatted("clip %llu has no motion (its frames are the same: pixels vary by %.3f grey "
                                       "levels over time, below %.2f): a frozen camera? not estimated",
                                       sequence, p.motion, clothwind::learn::kMinClipMotion)
                : clothwind::Formatted("clip %llu shows no scene (its picture's contrast is %.2f grey levels, below "
                                       "%.1f: noise or one level): a covered lens or darkness? not estimated",
                                       sequence, p.contrast, clothwind::learn::kMinClipContrast);
        if (first) clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);  // said at once, as an error is
        WALL_WARN_THROTTLE(30.0, "sdn_node: %s", still_clip_.c_str());
        clip_error_.clear();
        return;
      }
      still_clip_.clear();
      // Not published: a reader would average it into everything after it.
      if (!std::isfinite(p.speed) || !std::isfinite(p.speed_std))
        throw std::runtime_error("the estimate is not finite (speed " + std::to_string(p.speed) + " m/s, std " +
                                 std::to_string(p.speed_std) + " m/s)");
      const double latency = std::chrono::duration<double>(std::chrono::steady_clock::now() - received).count();
      const clothwind::WindEstimate estimate = clothwind::ros_bridge::ToWindEstimate(
          *clip, p, latency, model_name_, static_cast<uint32_t>(predictor_->config().frames));
      // In ROS time, so a replay's is the bag's: the delay a reader of the estimate sees, queue included.
      // In double seconds: ros::Time arithmetic throws beyond 32 bits (a clip stamped TIME_MAX).
      // Not a negative age: a clip of a looped bag's previous pass, estimated after the clock went
      // back, is the bag's length "in the future", and it skewed the mean over 50 clips.
      const double age = ros::Time::now().toSec() - estimate.clip_end.toSec();
      if (age >= 0) ages_.push_back(age);
      if (ages_.size() > 50) ages_.pop_front();
      estimate_pub_.publish(estimate);
      PublishMean(estimate, p.raw_speed);
      if (want_maps && !maps.power.empty()) PublishMaps(*clip, maps);
      ++estimates_;
      turned_ += p.turned;
      undecided_ += p.undecided;
      latencies_.push_back(latency);
      if (latencies_.size() > 50) latencies_.pop_front();
      last_estimate_wall_ = ros::SteadyTime::now().toSec();
      stamps_.push_back(last_estimate_wall_);
      TrimStamps(last_estimate_wall_);
      clip_error_.clear();
    } catch (const std::exception& e) {
      // Frames the model cannot read (a grey clip for a colour model, too few frames) are the
      // clip's fault as much as a wrong size; anything else is the model's.
      const bool malformed = dynamic_cast<const MalformedClip*>(&e) || dynamic_cast<const std::invalid_argument*>(&e);
      ++(malformed ? errors_ : model_errors_);
      last_error_ = "clip " + std::to_string(clip->sequence) + ": " + e.what();
      clip_error_ = (malformed ? "malformed clip: " : "the model failed on a clip: ") + last_error_;
      WALL_ERROR_THROTTLE(5.0, "sdn_node: %s", clip_error_.c_str());
      clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);
    }
  }

  // A clip that fails the message checks (ClipFrames, CheckClipFrameRate).
  struct MalformedClip : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
  };

  // The estimates' wall times over the last 30 s, for the rate.
  void TrimStamps(double now) {
    while (!stamps_.empty() && now - stamps_.front() > 30.0) stamps_.pop_front();
  }

  // The heading (FlyDirectionFromWind's) of the clip's camera from the latest transform of its optical
  // frame into the frame of the clip's wind direction: a camera's mount is fixed, and a clip's own
  // stamp is older than the first transform a static publisher sends. NaN, the reason kept for the
  // diagnostics, when there is none or the camera lies on its side.
  double CameraHeadingFromTf(const clothwind::Clip& clip) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (clip.header.frame_id.empty() || clip.wind_direction_frame_id.empty()) {
      pose_error_ = std::string("the clip names no ") +
                    (clip.header.frame_id.empty() ? "camera frame (header.frame_id)"
                                                  : "wind direction frame (wind_direction_frame_id)");
      return nan;
    }
    geometry_msgs::TransformStamped pose;
    try {
      pose = tf_buffer_->lookupTransform(clip.wind_direction_frame_id, clip.header.frame_id, ros::Time(0));
    } catch (const tf2::TransformException& e) {
      pose_error_ = std::string("no transform from '") + clip.header.frame_id + "' to '" +
                    clip.wind_direction_frame_id + "' in tf: " + e.what();
      return nan;
    }
    const auto& r = pose.transform.rotation;
    const auto heading = clothwind::learn::EquivalentCameraHeading(
        Eigen::Quaterniond(r.w, r.x, r.y, r.z).normalized().toRotationMatrix());
    if (!heading) {
      pose_error_ = "camera '" + clip.header.frame_id + "' lies on its side (its picture's right is more than 45 deg "
                    "out of the horizontal) in '" + clip.wind_direction_frame_id + "'";
      return nan;
    }
    pose_error_.clear();
    camera_heading_text_ = clothwind::Formatted("%.1f deg (tf: '%s' in '%s')", *heading * 180.0 / M_PI,
                                                clip.header.frame_id.c_str(), clip.wind_direction_frame_id.c_str());
    return *heading;
  }

  // ~flag_flies wind: the way the anemometer's wind makes the flag fly; a wind end-on to the
  // camera, or none, or no camera heading (NaN), keeps the way last known (as filmed until one is).
  void FollowTheWind(double wind_direction, double camera_heading) {
    const auto way = clothwind::learn::FlyDirectionFromWind(wind_direction, camera_heading, end_on_);
    if (!way) {
      ++wind_unknown_;
    } else {
      wind_told_ = true;
      predictor_->set_flag_flies(*way == clothwind::learn::FlyDirection::kRight ? clothwind::learn::FlagFlies::kRight
                                                                              : clothwind::learn::FlagFlies::kLeft);
    }
  }

  // The trailing mean up to this estimate; its clip_start is the first frame of the oldest clip
  // averaged, clip_end and the stamp those of this one. It averages the network's outputs before
  // the clamp at 0 (`raw_speed`) and clamps the mean: a mean of clamped calm estimates is biased up.
  // Clip time going back (a new bag, or a loop) starts it afresh.
  void PublishMean(const clothwind::WindEstimate& estimate, double raw_speed) {
    trailing_.Add(estimate.clip_end.toSec(), raw_speed, estimate.speed_std, estimate.clip_start.toNSec());
    clothwind::WindEstimate mean = estimate;
    mean.clip_start.fromNSec(trailing_.OldestTag());
    mean.speed = clothwind::learn::ClampSpeed(trailing_.Mean());
    mean.speed_std = trailing_.Std();
    mean.mean_window = trailing_.window();
    mean.mean_count = static_cast<uint32_t>(trailing_.Count());
    char model[64];
    std::snprintf(model, sizeof model, " [trailing %.0f s mean of %zu clips]", trailing_.window(), trailing_.Count());
    mean.model += model;
    mean_pub_.publish(mean);
  }

  void PublishMaps(const clothwind::Clip& clip, const clothwind::learn::PeakMaps& maps) {
    std_msgs::Header header = clip.header;
    header.stamp = clothwind::ros_bridge::ClipEnd(clip);
    if (power_pub_.getNumSubscribers() > 0) {
      cv::Mat log_power;
      cv::log(maps.power + 1.0f, log_power);
      double max = 0;
      cv::minMaxLoc(log_power, nullptr, &max);
      power_pub_.publish(clothwind::ros_bridge::BgrImageMsg(
          clothwind::learn::ColourMapped(log_power, 0, max > 0 ? max : 1, cv::COLORMAP_INFERNO), header));
    }
    if (frequency_pub_.getNumSubscribers() > 0) {
      frequency_pub_.publish(clothwind::ros_bridge::BgrImageMsg(
          clothwind::learn::FrequencyMapImage(maps, predictor_->config().frame_rate / 2), header));
    }
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    double mean = 0, max = 0;
    for (double l : latencies_) {
      mean += l;
      max = std::max(max, l);
    }
    if (!latencies_.empty()) mean /= latencies_.size();
    const double now = ros::SteadyTime::now().toSec();
    TrimStamps(now);
    // Estimates over the last 30 s: the intervals between them, N - 1 over the time they span
    // (N over the time since the first one overstated it until the window filled).
    const double rate =
        stamps_.size() > 1 ? (stamps_.size() - 1) / std::max(stamps_.back() - stamps_.front(), 1e-9) : 0.0;
    // Before the first estimate, the time since the model loaded: a node whose clips never come (a
    // wrong remap, no clip buffer) said OK "estimating" for ever.
    const double idle = estimates_ > 0 ? now - last_estimate_wall_ : predictor_ ? now - loaded_wall_ : 0.0;
    // An ERROR says one thing; every WARN that holds is said, joined (the idle WARN once hid the
    // others, and a node waiting for clips said nothing of its missing fly judge).
    const auto warn = diagnostic_msgs::DiagnosticStatus::WARN;
    if (!predictor_) {
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "no model: " + load_error_);
    } else if (!clip_error_.empty()) {
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR, clip_error_);
    } else {
      stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "estimating");
      if (idle > 10.0) {
        char what[112];
        std::snprintf(what, sizeof what, "%s for %.0f s (is the clip buffer, camera or bag running?)",
                      estimates_ > 0 ? "no clip" : "no clip received yet", idle);
        stat.mergeSummary(warn, what);
      }
      // Clips lost while estimating: the counter alone left an OK over a model slower than the
      // clips come, its queue dropping most of them.
      const uint64_t missing = sequence_gaps_.RecentMissing(now);
      if (missing > 0) {
        char what[224];
        std::snprintf(what, sizeof what,
                      "estimating; %llu clip%s missing from the sequence in the last 30 s (this node's ~queue_size "
                      "of %d overflowing while an estimate takes %.3g s, or lost upstream)",
                      static_cast<unsigned long long>(missing), missing == 1 ? "" : "s", queue_size_, mean);
        stat.mergeSummary(warn, what);
      }
      if (!still_clip_.empty()) stat.mergeSummary(warn, still_clip_);
      if (!judge_error_.empty()) stat.mergeSummary(warn, "estimating; ~fly_judge did not load: " + judge_error_);
      // ~flag_flies wind whose wind has never said the way (cups without a vane, a direction in
      // another frame than ~camera_heading_frame, the wind end-on): every clip is read as filmed,
      // and a flag flying left ~2.5 m/s wrong, under an OK.
      if (follow_wind_ && !wind_told_ && wind_unknown_ > 0)
        stat.mergeSummary(warn, "estimating; ~flag_flies wind: no clip's wind has said which way the flag flies (" +
                                    std::to_string(wind_unknown_) + " clips: no direction, the wind end-on" +
                                    (pose_from_tf_ ? ", no camera pose in tf" : "") +
                                    (last_wind_frame_.empty() ? std::string()
                                                              : ", or a direction in frame '" + last_wind_frame_ +
                                                                    "', not ~camera_heading_frame's '" +
                                                                    camera_heading_frame_ + "'") +
                                    "); clips are read as filmed");
      // The last clip's camera pose: without it the way is kept, and may go stale as the wind turns.
      if (pose_from_tf_ && !pose_error_.empty())
        stat.mergeSummary(warn, "estimating; ~flag_flies wind: " + pose_error_ + "; the way last known is kept");
      if (!predictor_->fly_judge_error().empty()) stat.mergeSummary(warn, "estimating; " + predictor_->fly_judge_error());
      if (!parameter_errors_.empty())
        stat.mergeSummary(warn, "estimating with a default for a parameter out of range: " + parameter_errors_.front());
      if (!predictor_->config().flips_in_training &&
          predictor_->flag_flies() == clothwind::learn::FlagFlies::kAuto && !predictor_->fly_judge()) {
        // A model trained without flips misreads a flag flying left by ~2.5 m/s, and the clip's own
        // motion misjudges the way of 7-9 % of FlagSim's clips (docs/sdn.md, "Flags that fly left").
        stat.mergeSummary(warn,
                          "estimating; the model knows only flags flying right and, with no fly judge, judges each "
                          "clip's way from its motion: set ~fly_judge, or ~flag_flies to right, left or wind");
      }
    }
    stat.add("model", model_name_.empty() ? model_path_ : model_name_);
    stat.add("device", predictor_ ? predictor_->device() : std::string("-"));
    stat.add("threads", threads_);
    stat.add("latency mean [s]", mean);
    stat.add("latency max [s]", max);
    stat.add("rate [clips/s]", rate);
    double age = 0;
    for (double a : ages_) age += a;
    stat.add("clip age at estimate, mean [s]", ages_.empty() ? 0.0 : age / ages_.size());
    stat.add("estimates", estimates_);
    const std::string way = predictor_ ? clothwind::learn::FlagFliesName(predictor_->flag_flies()) : "-";
    stat.add("flag flies", follow_wind_ ? "wind: " + way : way);
    if (predictor_) {
      const bool judge_asked = !follow_wind_ && predictor_->flag_flies() == clothwind::learn::FlagFlies::kAuto;
      stat.add("fly judge (for auto)",
               (predictor_->fly_judge() ? predictor_->fly_judge_path().string()
                                        : std::string("none: the clip's motion cues")) +
                   (judge_asked ? "" : " (not asked: ~flag_flies is " + (follow_wind_ ? "wind" : way) + ")"));
    }
    if (follow_wind_) {
      stat.add("camera heading", !pose_from_tf_ ? "~camera_heading " + std::to_string(camera_heading_) + " rad" +
                                                      (camera_heading_frame_.empty() ? std::string()
                                                                                     : " in '" + camera_heading_frame_ + "'")
                                 : !pose_error_.empty()        ? pose_error_
                                 : camera_heading_text_.empty() ? std::string("tf: no clip with a wind direction yet")
                                                                : camera_heading_text_);
      stat.add("clips with the wind end-on or unknown", wind_unknown_);
    }
    stat.add("clips turned round (flag flying left)", turned_);
    stat.add("clips the fly judge could not tell (the last way kept)", undecided_);
    stat.add("clips without motion (not estimated)", no_motion_);
    stat.add("clips without a scene (not estimated)", no_scene_);
    stat.add("trailing mean [m/s]", trailing_.Mean());
    stat.add("clips in the trailing mean", trailing_.Count());
    stat.add("malformed clips", errors_);
    stat.add("clips the model failed on", model_errors_);
    stat.add("clips dropped (no model)", dropped_);
    stat.add("clips missing from the sequence (queue or upstream)", sequence_gaps_.Missing());
    stat.add("trailing mean restarts (clip time went back)", trailing_.Restarts());
    stat.add("seconds since the last estimate", idle);
    stat.add("last error", last_error_);
    std::string parameters;
    for (const std::string& e : parameter_errors_) parameters += (parameters.empty() ? "" : "; ") + e;
    stat.add("parameter errors", parameters.empty() ? std::string("none") : parameters);
  }

  image_transport::ImageTransport transport_;
  ros::Publisher estimate_pub_, mean_pub_;
  image_transport::Publisher power_pub_, frequency_pub_;
  ros::Subscriber clip_sub_;
  diagnostic_updater::Updater updater_;
  ros::SteadyTimer diag_timer_, load_timer_;
  std::string model_path_, device_, model_name_, load_error_, last_error_;
  std::string fly_judge_path_, judge_error_;  // ~fly_judge and why it did not load
  std::optional<clothwind::learn::FlagFlies> told_flag_flies_;  // ~flag_flies right, left or auto
  bool follow_wind_ = false;                                     // ~flag_flies wind
  bool wind_told_ = false;          // with follow_wind_: some clip's wind has said the way
  std::string last_wind_frame_;     // the last clip wind direction frame that was not ~camera_heading_frame's
  std::string camera_heading_frame_;  // the frame ~camera_heading is in ("": the clips' own)
  double camera_heading_ = 0, end_on_ = 0;                       // [rad], for follow_wind_
  bool pose_from_tf_ = false;  // follow_wind_ with ~camera_heading unset: the camera's pose in tf
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;  // only then: no /tf subscription otherwise
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::string pose_error_;           // why the last clip had no camera heading from tf ("": it had)
  std::string camera_heading_text_;  // the last heading from tf, with its frames
  int threads_ = 2;
  std::unique_ptr<clothwind::learn::Predictor> predictor_;
  int queue_size_ = 2;
  clothwind::sensors::SequenceGaps sequence_gaps_;  // clips missing, on the wall clock
  std::deque<double> latencies_, stamps_, ages_;  // ages_: [s] ROS time from clip end to its estimate
  clothwind::sensors::TrailingMean trailing_;  // tagged with each clip's start [ns]
  uint64_t estimates_ = 0, errors_ = 0, model_errors_ = 0, dropped_ = 0, turned_ = 0, undecided_ = 0,
           wind_unknown_ = 0, no_motion_ = 0, no_scene_ = 0;
  std::string still_clip_;  // why the last clip was not estimated (no motion or scene); cleared by an estimate
  double last_estimate_wall_ = 0;                  // [s] wall time of the last estimate
  double loaded_wall_ = 0;                         // [s] wall time the model loaded
  std::string clip_error_;                          // the last clip's failure; cleared by a good clip
  std::vector<std::string> parameter_errors_;       // parameters out of range (their defaults used)
  static inline std::string mean_window_error_;     // MeanWindow runs before the members exist
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "sdn_node");
  ros::NodeHandle nh, pnh("~");
  clothwind::ros_bridge::StrictParams params(pnh);
  std::unique_ptr<SdnNode> node;
  try {
    clothwind::ros_bridge::CheckDiagnosticPeriod(params);  // before SdnNode's diagnostic_updater reads it
    node = std::make_unique<SdnNode>(nh, params);
  } catch (const clothwind::ros_bridge::ParamError& e) {
    ROS_FATAL("sdn_node: %s", e.what());
    return 1;
  }
  params.WarnUnread("sdn_node");
  ros::spin();
  return 0;
}
