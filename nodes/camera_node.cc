// camera_node: frames from a V4L2 camera (or, for tests and bench work, a video file or an image
// folder played at its native rate) published as camera/image_raw + camera/camera_info.
//
// Publishes   camera/image_raw (sensor_msgs/Image, mono8 for GREY, bgr8 otherwise; through
//             image_transport), camera/camera_info (sensor_msgs/CameraInfo, same stamp),
//             /diagnostics (rate and stamp age of camera/image_raw, source state, negotiated
//             format, dropped and unreadable frames, reconnects)
// Services    camera/set_camera_info (camera_calibration's COMMIT: used at once, and stored at
//             ~camera_info_url through a temporary file; success false, saying why, when it is not)
// Parameters  ~source (v4l2 | video | folder), ~device (/dev/video0), ~path (video file or image
//             folder), ~pixel_format (YUYV | MJPEG | GREY), ~width, ~height [px], ~fps [Hz],
//             ~rate [Hz] (folder rate; default ~fps), ~loop, ~buffers, ~timeout [s],
//             ~auto_exposure (bool), ~exposure_absolute [100 us], ~gain, ~frame_id
//             (camera_optical_frame), ~camera_name (camera), ~camera_info_url
// Frame stamps are capture instants from the driver's buffer timestamps mapped to ROS time
// (src/sensors/frame_timestamp.h), not the time of publishing. A calibration file the parser
// cannot read (a folder, a matrix of another shape) is refused before camera_info_manager reads
// it, and camera_info goes out without calibration (ros_bridge/camera_calibration_file.h). A
// parameter of the wrong type ends the node at start (ros_bridge/strict_param.h). See
// docs/camera.md.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <camera_info_manager/camera_info_manager.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/publisher.h>
#include <image_transport/image_transport.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <sensor_msgs/SetCameraInfo.h>

#include "common/atomic_file.h"
#include "ros_bridge/camera_calibration_file.h"
#include "ros_bridge/image_conversions.h"
#include "ros_bridge/ros_log.h"
#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "ros_bridge/wall_throttle.h"
#include "sensors/backoff.h"
#include "sensors/frame_read_tally.h"
#include "sensors/frame_source.h"
#include "sensors/frame_source_factory.h"
#include "sensors/frame_timestamp.h"

namespace {

using clothwind::sensors::Frame;
using clothwind::sensors::FrameSource;
using clothwind::sensors::FrameSourceOptions;
using clothwind::sensors::ReadStatus;

// Monotonic clock from the system, "ROS time" from ros::Time::now() (the wall clock, or /clock
// under use_sim_time), so stamps are in the time base every subscriber compares against.
class RosClock : public clothwind::sensors::SystemClock {
 public:
  int64_t RosNs() override { return static_cast<int64_t>(ros::Time::now().toNSec()); }
  bool RosTimeIsSimulated() override { return ros::Time::isSimTime(); }
};

// Every parameter is read whatever ~source says (config/camera.yaml sets both ~device and ~path):
// each is type-checked, and none is named unread at start for belonging to another source.
FrameSourceOptions ReadOptions(clothwind::ros_bridge::StrictParams& params) {
  FrameSourceOptions o;
  o.source = params.Get("source", "v4l2");
  const std::string device = params.Get("device", "/dev/video0");
  const std::string path = params.Get("path", "");
  o.path = o.source == "v4l2" ? device : path;
  o.pixel_format = params.Get("pixel_format", "YUYV");
  o.width = params.Get("width", 640);
  o.height = params.Get("height", 480);
  o.fps = params.Get("fps", 30.0);
  const double rate = params.Get("rate", o.fps);
  if (o.source == "folder") o.fps = rate;
  o.buffers = params.Get("buffers", 4);
  o.timeout_s = params.Get("timeout", 2.0);
  o.loop = params.Get("loop", false);
  if (params.Has("auto_exposure"))  // unset: the camera's own setting (-1)
    o.auto_exposure = params.Get("auto_exposure", false) ? 1 : 0;
  o.exposure_absolute = params.Get("exposure_absolute", -1);
  o.gain = params.Get("gain", -1);
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "camera_node");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");

  clothwind::ros_bridge::StrictParams params(pnh);
  FrameSourceOptions options;
  std::string frame_id, camera_name, camera_info_url;
  try {
    options = ReadOptions(params);
    frame_id = params.Get("frame_id", "camera_optical_frame");
    camera_name = params.Get("camera_name", "camera");
    camera_info_url = params.Get("camera_info_url", "");
    clothwind::ros_bridge::CheckDiagnosticPeriod(params);  // read by diagnostic_updater below
  } catch (const std::exception& e) {
    ROS_FATAL("camera_node: %s", e.what());
    return 1;
  }

  RosClock clock;
  std::string error;
  std::unique_ptr<FrameSource> source = clothwind::sensors::MakeFrameSource(options, &clock, clothwind::ros_bridge::RosLog, &error);
  if (!source) {
    ROS_FATAL_STREAM("camera_node: bad parameters: " << error);
    return 1;
  }

  ros::NodeHandle camera_nh(nh, "camera");
  // Given the URL, where set_camera_info (the calibration tool's COMMIT) saves: constructed with
  // none, a calibration committed while ~camera_info_url was refused went to the default file,
  // which the next start, refusing the URL again, never read. The manager reads its URL lazily,
  // so the file is checked first (see ros_bridge/camera_calibration_file.h), as a folder or a
  // matrix of another shape aborted the node inside the parser, and a refused file is replaced
  // by an empty calibration before anything asks for it. A refused file leaves camera_info
  // without calibration, said in diagnostics, rather than falling back to camera_info_manager's
  // default file, which is not the calibration asked for either; a COMMIT then writes the URL's
  // file, or answers that it cannot. The manager serves set_camera_info in the namespace it is
  // given: given one of its own, which no tool calls, and camera/set_camera_info is served below. Its writer truncated the file in
  // place and answered success whatever the write did (camera_calibration_parsers: "always
  // returns true"), so a full disk or a crash mid-write lost the calibration the tool was told
  // was stored.
  ros::NodeHandle manager_nh(camera_nh, "camera_info_manager");
  camera_info_manager::CameraInfoManager info_manager(manager_nh, camera_name, camera_info_url);
  const std::string url = camera_info_url.empty() ? clothwind::ros_bridge::kDefaultCameraInfoUrl : camera_info_url;
  const std::string calibration_path =
      clothwind::ros_bridge::CalibrationFilePath(info_manager.resolveURL(url, camera_name), ros::package::getPath);
  const std::string calibration_refused = clothwind::ros_bridge::CheckCalibrationFile(calibration_path);
  std::error_code no_file;
  if (calibration_refused.empty() && !calibration_path.empty() && !std::filesystem::exists(calibration_path, no_file)) {
    // None yet (set_camera_info writes it): no calibration. The default file's absence is no
    // news (camera_info_manager's own load warned "not found" at every start); a URL given is
    // said, as a mistyped path would otherwise pass for an uncalibrated camera.
    info_manager.setCameraInfo(sensor_msgs::CameraInfo());
    if (!camera_info_url.empty())
      ROS_WARN_STREAM("camera_node: no calibration file at '" << camera_info_url
                      << "' yet (set_camera_info writes it there); camera_info carries the image size only");
  } else if (calibration_refused.empty()) {
    info_manager.loadCameraInfo(camera_info_url);
    if (!camera_info_url.empty() && !info_manager.isCalibrated()) {
      ROS_WARN_STREAM("camera_node: no calibration loaded from '" << camera_info_url
                      << "'; camera_info carries the image size only");
    }
  } else {
    // An empty calibration, set: the manager loads nothing more (set_camera_info still stores a
    // new one, at ~camera_info_url).
    info_manager.setCameraInfo(sensor_msgs::CameraInfo());
    ROS_WARN_STREAM("camera_node: calibration not loaded from '" << url << "'"
                    << (camera_info_url.empty() ? " (~camera_info_url empty: camera_info_manager's default)" : "")
                    << ": " << calibration_refused
                    << "; publishing camera_info without calibration");
  }
  // set_camera_info: the calibration is used from now on (as camera_info_manager did) and stored
  // whole or not at all, the answer saying which.
  ros::ServiceServer set_camera_info = camera_nh.advertiseService<sensor_msgs::SetCameraInfo::Request,
                                                                  sensor_msgs::SetCameraInfo::Response>(
      "set_camera_info", [&](sensor_msgs::SetCameraInfo::Request& req, sensor_msgs::SetCameraInfo::Response& rsp) {
        info_manager.setCameraInfo(req.camera_info);
        rsp.success = false;
        if (calibration_path.empty()) {
          rsp.status_message = "the calibration is used but not stored: " + url + " is not a file:// or package:// URL";
        } else {
          try {
            // In the format its extension names: YAML written into a .ini was unreadable at the
            // next start.
            const std::string text =
                clothwind::ros_bridge::CalibrationFileText(calibration_path, camera_name, req.camera_info);
            std::error_code ec;
            std::filesystem::create_directories(std::filesystem::path(calibration_path).parent_path(), ec);
            clothwind::WriteFileAtomically(calibration_path, text);
            rsp.success = true;
            rsp.status_message = "stored in " + calibration_path;
          } catch (const std::exception& e) {
            rsp.status_message = std::string("the calibration is used but not stored: ") + e.what();
          }
        }
        if (rsp.success)
          ROS_INFO_STREAM("camera_node: calibration " << rsp.status_message);
        else
          ROS_ERROR_STREAM("camera_node: " << rsp.status_message);
        return true;
      });
  image_transport::ImageTransport transport(nh);
  image_transport::CameraPublisher publisher = transport.advertiseCamera("camera/image_raw", 1);
  // After advertising: a node named "camera" publishes /camera/image_raw, where image_transport's
  // plugins keep their parameters (~image_raw/compressed/...), which are not misspelt keys.
  params.WarnUnread("camera_node");

  diagnostic_updater::Updater updater;
  clothwind::ros_bridge::WallDiagnostics wall_diagnostics(&updater);  // every wall second
  updater.setHardwareID(options.source == "v4l2" ? options.path : options.source + ":" + options.path);
  double min_rate = options.fps, max_rate = options.fps;  // the nominal rate, once known
  // Stamps are capture instants: a little in the past (latency), never in the future.
  diagnostic_updater::TopicDiagnostic topic_diagnostic(
      "camera/image_raw", updater,
      diagnostic_updater::FrequencyStatusParam(&min_rate, &max_rate, 0.1, 10),
      diagnostic_updater::TimeStampStatusParam(-0.05, 0.5));
  uint64_t published = 0, last_drops_seen = 0;
  uint64_t unsubscribed = 0;  // frames read while nobody subscribed (no message built)
  // Frames that came but could not be read, apart from failures of the source itself.
  clothwind::sensors::FrameReadTally tally;
  std::string last_error;  // why the source last failed to open or read
  // Why the calibration is left out of camera_info ("" if it is not): the refused file's reason
  // from the start (the diagnostics say it before a frame comes), then each frame's.
  std::string calibration_unused =
      calibration_refused.empty() ? "" : "calibration file refused: " + calibration_refused;
  bool opened = false, ended = false;
  uint64_t opens = 0;  // successful Opens (a recording that failed is opened again)
  updater.add("camera source", [&](diagnostic_updater::DiagnosticStatusWrapper& stat) {
    const auto status = source->Status();
    for (const auto& kv : status) stat.add(kv.first, kv.second);
    stat.add("published", published);
    stat.add("read with no subscriber (not published)", unsubscribed);
    stat.add("unreadable frames", tally.bad_frames());
    stat.add("source failures (device lost, reopen failed, recording unreadable)", tally.failures());
    stat.add("frame_id", frame_id);
    stat.add("calibration", !calibration_unused.empty()         ? "left out: " + calibration_unused
                            : info_manager.isCalibrated() ? std::string("published")
                                                          : std::string("none (image size only)"));
    const auto state = status.count("state") ? status.at("state") : std::string("?");
    uint64_t drops = 0;
    if (status.count("dropped frames")) drops = std::stoull(status.at("dropped frames"));
    const std::vector<std::string> read_warnings = tally.TakeReport();
    if (!opened) {
      // A recording that opened and then failed (nothing in it readable) is not one that cannot
      // be opened.
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR,
                   (opens > 0 ? "failed, opening again: " : "cannot open: ") + last_error);
    } else if (ended) {
      stat.summary(diagnostic_msgs::DiagnosticStatus::WARN, "recording ended");
    } else if (state != "streaming" && state != "open") {
      stat.summary(diagnostic_msgs::DiagnosticStatus::ERROR, state + ": " + last_error);
    } else {
      stat.summary(diagnostic_msgs::DiagnosticStatus::OK, state + ": " + source->Describe());
      // Recordings are paced on /clock under use_sim_time (FramePacer): none comes before it.
      if (ros::Time::isSimTime() && ros::Time::now().isZero())
        stat.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN,
                          "use_sim_time is set and no /clock has come yet: frames wait for it");
      if (!calibration_unused.empty())
        stat.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN,
                          "camera_info without calibration: " + calibration_unused);
      if (drops > last_drops_seen)
        stat.mergeSummaryf(diagnostic_msgs::DiagnosticStatus::WARN, "%llu frames dropped since last report",
                           static_cast<unsigned long long>(drops - last_drops_seen));
      // Frames the driver flagged corrupt or that would not decode (the stream runs, but not all of
      // it reaches the clips), and a loss healed within the report period.
      for (const std::string& warning : read_warnings)
        stat.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, warning);
    }
    last_drops_seen = drops;
  });

  // The rate check measures its window in ROS time: after /clock went back (a bag looped) or
  // first started, its windows spanned the jump (negative, or from time 0) and it said "Frequency
  // too low" for ten reports. Cleared at each jump, as the clip buffer restarts.
  ros::Time last_ros_now = ros::Time::now();
  auto update_diagnostics = [&] {
    const ros::Time now = ros::Time::now();
    if (now < last_ros_now || (last_ros_now.isZero() && !now.isZero())) topic_diagnostic.clear_window();
    last_ros_now = now;
    wall_diagnostics.Update();
  };
  clothwind::sensors::Backoff open_backoff(0.25, 5.0);  // [s] between attempts to open the source
  ros::SteadyTime next_open;  // steady: a wall clock stepped back by NTP held the reopen until it caught up
  while (ros::ok()) {
    if (!opened) {
      // Wait for the next attempt in short slices: diagnostics and services (set_camera_info)
      // keep running while the device is away (a single sleep of up to 5 s stalled them).
      if (ros::SteadyTime::now() < next_open) {
        ros::WallDuration(std::min(0.1, (next_open - ros::SteadyTime::now()).toSec())).sleep();
        update_diagnostics();
        ros::spinOnce();
        continue;
      }
      if (source->Open()) {
        opened = true;
        const double rate = source->NominalRate();
        if (rate > 0) min_rate = max_rate = rate;
        if (opens++ == 0) {
          ROS_INFO_STREAM("camera_node: publishing " << source->Describe() << " on "
                          << publisher.getTopic() << " in frame " << frame_id);
        } else {
          WALL_WARN_STREAM_THROTTLE(10.0, "camera_node: opened " << source->Describe() << " again after: "
                                                                 << last_error);
        }
      } else {
        last_error = source->error();
        tally.SourceFailed(last_error);
        WALL_ERROR_STREAM_THROTTLE(5.0, "camera_node: " << last_error << " (retrying)");
        update_diagnostics();
        next_open = ros::SteadyTime::now() + ros::WallDuration(open_backoff.Next());
        ros::spinOnce();
        continue;
      }
    }
    if (ended) {
      ros::WallDuration(0.1).sleep();
    } else {
      Frame frame;
      const ReadStatus status = source->Read(&frame, 0.1);
      const bool failed = status == ReadStatus::kBadFrame || status == ReadStatus::kError;
      tally.Record(status, failed ? source->error() : std::string());
      if (status == ReadStatus::kFrame) open_backoff.Reset();  // reading again: the next failure retries soon
      if (status == ReadStatus::kFrame && publisher.getNumSubscribers() == 0) {
        // The frame is read and decoded (the driver's buffers must keep moving) and counted at the
        // camera's rate, but no message is built for nobody.
        topic_diagnostic.tick(clothwind::ros_bridge::RosTimeFromNs(frame.stamp_ns));
        ++unsubscribed;
      } else if (status == ReadStatus::kFrame) {
        try {
          sensor_msgs::ImagePtr image = clothwind::ros_bridge::ToImageMsg(frame, frame_id);
          std::string unused_reason;
          sensor_msgs::CameraInfoPtr info =
              clothwind::ros_bridge::CameraInfoFor(info_manager.getCameraInfo(), *image, &unused_reason);
          // A refused file stays the reason until set_camera_info brings a calibration.
          if (unused_reason.empty() && !calibration_refused.empty() && !info_manager.isCalibrated())
            unused_reason = "calibration file refused: " + calibration_refused;
          if (unused_reason != calibration_unused) {  // once per new reason (set_camera_info may change it)
            if (!unused_reason.empty())
              ROS_WARN_STREAM("camera_node: " << unused_reason << "; publishing camera_info without it");
            calibration_unused = unused_reason;
          }
          publisher.publish(image, info);
          topic_diagnostic.tick(image->header.stamp);
          ++published;
          const double rate = source->NominalRate();  // may change after a reconnect
          if (rate > 0) min_rate = max_rate = rate;
        } catch (const std::exception& e) {
          tally.BadFrame(e.what());
          WALL_ERROR_STREAM_THROTTLE(2.0, "camera_node: " << e.what());
        }
      } else if (status == ReadStatus::kBadFrame) {
        WALL_WARN_STREAM_THROTTLE(2.0, "camera_node: " << source->error());
      } else if (status == ReadStatus::kError) {
        last_error = source->error();
        WALL_WARN_STREAM_THROTTLE(2.0, "camera_node: " << last_error);
        if (!source->IsOpen()) {
          // A recording that became unreadable: Open again, with a backoff that grows until a
          // frame is read (a folder whose files all fail still opens, and reopening it at once
          // spun through it thousands of times a second).
          opened = false;
          next_open = ros::SteadyTime::now() + ros::WallDuration(open_backoff.Next());
        }
      } else if (status == ReadStatus::kEnd) {
        ended = true;
        ROS_INFO_STREAM("camera_node: end of " << source->Describe() << " after " << published
                        << " frames (set ~loop to repeat)");
      }
    }
    update_diagnostics();
    ros::spinOnce();
  }
  // SIGINT/shutdown: STREAMOFF, munmap, close before exiting.
  source->Close();
  return 0;
}
