// clip_buffer_node: camera frames + anemometer readings in, labelled 25 fps clips out.
//
// Subscribes  camera/image_raw (sensor_msgs/Image), camera/camera_info (kept for recorded
//             clips' metadata), anemometer/wind (clothwind/WindMeasurement)
// Publishes   clips (clothwind/Clip), clips/preview (sensor_msgs/Image mono8, or bgr8 with
//             ~colour: the latest clip's middle frame, only built while someone subscribes),
//             /diagnostics
// All the logic is in sensors::ClipPipeline and sensors::ClipRecording (see docs/clips.md): the
// recording folder is opened, reopened when lost and drained at shutdown there, and clips are
// written on a thread of their own (sensors::AsyncDatasetWriter), so a slow disk never holds up
// the camera callback.
#include <chrono>
#include <cmath>
#include <csignal>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <clothwind/Clip.h>
#include <clothwind/WindMeasurement.h>

#include "common/formatted.h"
#include "ros_bridge/clip_conversions.h"
#include "ros_bridge/ros_log.h"
#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "ros_bridge/wall_throttle.h"
#include "sensors/clip_pipeline.h"
#include "sensors/clip_recording.h"
#include "sensors/dataset_writer.h"
#include "sensors/wind_direction_frame.h"

namespace clothwind {
namespace {

class ClipBufferNode {
 public:
  ClipBufferNode(ros::NodeHandle& nh, ros_bridge::StrictParams& params) : nh_(nh) {
    sensors::ClipPipelineOptions o;
    o.frame_rate = params.Get("frame_rate", o.frame_rate);
    o.num_frames = params.Get("num_frames", o.num_frames);
    o.stride = params.Get("stride", o.stride);
    o.size = params.Get("size", o.size);
    o.colour = params.Get("colour", o.colour);
    o.gap_tolerance = params.Get("gap_tolerance", o.gap_tolerance);
    o.label_window = params.Get("label_window", o.label_window);
    o.label_delay = params.Get("label_delay", o.label_delay);
    o.max_future = params.Get("max_future", o.max_future);
    const std::vector<double> roi = params.Get("roi", std::vector<double>());
    if (roi.size() != 3 && !roi.empty())
      throw std::invalid_argument("~roi: expected a list [x, y, size] in source pixels (or [] for the centred "
                                  "square)");
    if (roi.size() == 3) {
      // Whole pixels in range, taken as given: 10.6 was rounded without a word, 3e9 wrapped to a
      // negative number the error then showed, and x, y beside size 0 were dropped for the
      // centred square.
      for (double v : roi)
        if (!(v >= 0 && v <= 1 << 20 && v == std::floor(v)))
          throw std::invalid_argument("~roi: expected [x, y, size] in whole source pixels from 0 to 1048576, got [" +
                                      Formatted("%.15g, %.15g, %.15g", roi[0], roi[1], roi[2]) + "]");
      if (roi[2] == 0 && (roi[0] != 0 || roi[1] != 0))
        throw std::invalid_argument("~roi: size 0 means the centred square, which takes no x, y; got [" +
                                    Formatted("%.15g, %.15g", roi[0], roi[1]) + ", 0] (give a size, or [])");
      o.roi = {static_cast<int>(roi[0]), static_cast<int>(roi[1]), static_cast<int>(roi[2])};
    }
    flush_after_ = params.Get("flush_after", 3.0);
    frame_id_ = params.Get("frame_id", "");
    wind_frame_ = sensors::WindDirectionFrameGate(params.Get("wind_frame_id", ""));
    const int queue = params.Get("queue_size", 60);
    jpeg_quality_ = params.Get("jpeg_quality", jpeg_quality_);
    index_interval_ = params.Get("index_interval", index_interval_);
    // An int is taken as its text (roslaunch makes one of record_dir:=20261206): read as a
    // string, that left record_dir empty and recorded nothing, without a word.
    record_dir_ = params.Get("record_dir", "");
    // Relative to the node's working folder, which roslaunch makes ROS_HOME (~/.ros): days of clips
    // went there, onto the home partition, under a name that looked like the field disk's.
    record_dir_ = ros_bridge::AbsolutePathParam("clip_buffer: ~record_dir", record_dir_);
    // Out of range is refused at start, naming the parameter: a clip buffer that runs with a
    // setting it did not mean records data that looks right and is not.
    if (!(std::isfinite(flush_after_) && flush_after_ > 0.0))
      throw std::invalid_argument("~flush_after must be a finite time > 0 s, got " + std::to_string(flush_after_));
    if (queue < 1) throw std::invalid_argument("~queue_size must be >= 1, got " + std::to_string(queue));
    if (jpeg_quality_ < 1 || jpeg_quality_ > 100)
      throw std::invalid_argument("~jpeg_quality must be in 1..100, got " + std::to_string(jpeg_quality_));
    if (!(index_interval_ >= 0 && index_interval_ <= 86400))
      throw std::invalid_argument("~index_interval must be in 0..86400 s, got " + std::to_string(index_interval_));
    try {
      pipeline_ = std::make_unique<sensors::ClipPipeline>(o);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("~") + e.what());
    }
    // A record folder that cannot be opened (a disk not mounted yet, a damaged index) stops the
    // recording, not the clips: the node publishes, says why in its diagnostics and retries.
    sensors::ClipRecording::Options recording;
    recording.dir = record_dir_;
    recording.jpeg_quality = jpeg_quality_;
    recording.index_interval = index_interval_;
    recording_ = std::make_unique<sensors::ClipRecording>(
        recording,
        [](sensors::LogLevel level, const std::string& text) { ros_bridge::RosLog(level, "clip_buffer: " + text); },
        ros::SteadyTime::now().toSec());

    clip_pub_ = nh.advertise<clothwind::Clip>("clips", 4);
    preview_pub_ = nh.advertise<sensor_msgs::Image>("clips/preview", 1, true);
    image_sub_ = nh.subscribe("camera/image_raw", queue, &ClipBufferNode::OnImage, this,
                              ros::TransportHints().tcpNoDelay());
    info_sub_ = nh.subscribe("camera/camera_info", 1, &ClipBufferNode::OnCameraInfo, this);
    wind_sub_ = nh.subscribe("anemometer/wind", 200, &ClipBufferNode::OnWind, this);
    source_.description = "clip_buffer_node " + image_sub_.getTopic();

    updater_.setHardwareID("clip_buffer");
    updater_.add("clip buffer", this, &ClipBufferNode::Diagnose);
    flush_timer_ = nh.createSteadyTimer(ros::WallDuration(0.25), &ClipBufferNode::OnTimer, this);
    ROS_INFO("clip_buffer: %d frames at %.1f fps every %d frames, %dx%d %s, roi %s, label window %.0f s (delay %.1f s), "
             "gap tolerance %.3f s",
             o.num_frames, o.frame_rate, o.stride, o.size, o.size, sensors::ClipFrameEncoding(o.colour),
             o.roi.size > 0 ? ("[" + std::to_string(o.roi.x) + ", " + std::to_string(o.roi.y) + ", " +
                               std::to_string(o.roi.size) + "]").c_str()
                            : "centre square",
             o.label_window, o.label_delay, o.gap_tolerance);
  }

  // Labels and records whatever is still waiting (called on shutdown; nothing is published then).
  // The last clips wait for room in the writer's queue (a full queue of a slow disk dropped them
  // with no report after), for kShutdownBudget s at most: roslaunch sends SIGTERM 15 s after
  // Ctrl-C and SIGKILL 2 s later, and a kill mid-way lost the clips on disk since the last
  // index rewrite with no word (the writer now lists each clip as it lands). Clips given up are
  // named, and the tally, with the last write or index error, is said at the end.
  void Finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                 std::chrono::duration<double>(kShutdownBudget));
    const auto waiting = pipeline_->Flush();
    UpdateSource();
    recording_->Finish(waiting, source_, deadline);
  }

 private:
  void OnImage(const sensor_msgs::ImageConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_input_ = ros::SteadyTime::now();
    last_image_ = last_input_;
    recording_->InputArrived();
    // An unstamped frame is dropped before it touches anything: taken as a bag loop, one frame
    // stamped 0 forgot the minute of readings the labels need (and lent the clips its frame_id).
    if (msg->header.stamp.isZero()) {
      NoteError("frame dropped: header.stamp is 0 (unstamped camera driver?)");
      return;
    }
    // Within ROS time with a clip's span to spare: a clip ending beyond 2^32 s could not be stamped
    // (ros::Time threw), which ended the node when no clock could refuse the frame as future.
    if (msg->header.stamp.toSec() > kLatestStamp) {
      NoteError("frame dropped: header.stamp " + std::to_string(msg->header.stamp.toSec()) +
                " s is beyond ROS time (TIME_MAX?)");
      return;
    }
    if (frame_id_.empty() || frame_id_from_msg_) {
      frame_id_ = msg->header.frame_id;
      frame_id_from_msg_ = true;
    }
    try {
      cv::Mat view;
      sensors::ClipSourceEncoding encoding;
      ros_bridge::ImageView(*msg, &view, &encoding);
      const uint64_t future_before = pipeline_->stats().frames_future;
      if (!pipeline_->AddFrame(msg->header.stamp.toSec(), view, encoding, Now()) &&
          pipeline_->stats().frames_future > future_before) {  // not the previous pass's
        last_future_ = ros::SteadyTime::now();
        WALL_WARN_THROTTLE(5.0, "clip_buffer: frame stamped %.1f s after the clock refused (camera clock?)",
                          pipeline_->stats().last_future_lead);
      }
    } catch (const std::exception& e) {
      NoteError(std::string("frame dropped: ") + e.what());
    }
    Publish(pipeline_->TakeReady());
  }

  void OnWind(const clothwind::WindMeasurement::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_input_ = ros::SteadyTime::now();
    recording_->InputArrived();
    if (msg->header.stamp.isZero()) {
      NoteError("anemometer reading dropped: header.stamp is 0");
      return;
    }
    const sensors::ClipPipelineStats before = pipeline_->stats();
    sensors::LabelReading reading = ros_bridge::ToLabelReading(*msg);
    const double direction = reading.direction;
    // Directions in another frame than the labels' are left out of the mean (speeds are kept). A
    // reading the labels skip (void, or no speed) neither counts nor picks the frame, nor does one
    // the pipeline refuses (stamped in the future, or too late): the frame is adopted only with
    // a reading the labels take.
    const bool labelled = std::isfinite(reading.speed);
    const bool same_frame = wind_frame_.Accepts(msg->header.frame_id, direction);
    if (labelled && !same_frame) {
      wind_frame_.Admit(msg->header.frame_id, direction);  // counted
      reading.direction = std::numeric_limits<double>::quiet_NaN();
      WALL_WARN_THROTTLE(10.0, "clip_buffer: wind direction in frame '%s' left out of the labels, which average "
                        "directions in '%s' (~wind_frame_id)", msg->header.frame_id.c_str(),
                        wind_frame_.frame_id().c_str());
    }
    pipeline_->AddReading(reading, Now());
    const bool future = pipeline_->stats().readings_future > before.readings_future;
    const bool refused = future || pipeline_->stats().readings_late > before.readings_late;
    if (labelled && same_frame && !refused) wind_frame_.Admit(msg->header.frame_id, direction);
    if (future) {
      last_future_ = ros::SteadyTime::now();
      WALL_WARN_THROTTLE(5.0, "clip_buffer: anemometer reading stamped %.1f s after the clock refused",
                        pipeline_->stats().last_future_lead);
    }
    Publish(pipeline_->TakeReady());
  }

  void OnCameraInfo(const sensor_msgs::CameraInfo::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!recording_->open()) return;
    source_.camera = ros_bridge::CameraInfoJson(*msg);
  }

  // The stream stalled or ended (end of a bag): label what waits with the readings held now.
  void OnTimer(const ros::SteadyTimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pipeline_->pending() > 0 && (ros::SteadyTime::now() - last_input_).toSec() > flush_after_) {
      ROS_INFO("clip_buffer: no input for %.1f s, labelling %zu waiting clip(s) with the readings held",
               flush_after_, pipeline_->pending());
      Publish(pipeline_->Flush());
    }
    // The folder lost (a disk unplugged, or replugged and mounted again) is reopened once it is
    // back; input stopped (a replay ended), the clips recorded since the last index rewrite are
    // listed now rather than after ~index_interval (after the clips just flushed).
    const bool idle = (ros::SteadyTime::now() - last_input_).toSec() > flush_after_;
    for (const std::string& problem : recording_->Poll(ros::SteadyTime::now().toSec(), idle)) NoteError(problem);
    // force_update once a wall second: Updater::update() waits for ROS time, which stands still
    // while a bag is paused and jumps back when it loops. (WallThrottle: again at once after the
    // wall clock steps back, which held every report until it caught up.)
    if (diagnostics_throttle_.Due(diagnostic_period_)) clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);
  }

  void Publish(const std::vector<sensors::LabelledClip>& clips) {
    for (const auto& c : clips) {
      // One clip that cannot be converted (a stamp ROS time cannot hold) costs that clip, said in
      // diagnostics, not the node (Publish also runs from the wall timer, outside any handler).
      try {
        PublishOne(c);
      } catch (const std::exception& e) {
        NoteError("clip " + std::to_string(c.clip.sequence) + " dropped: " + e.what());
      }
    }
  }

  void PublishOne(const sensors::LabelledClip& c) {
    if (c.label.count == 0)
      WALL_WARN_THROTTLE(10.0, "clip_buffer: clip %lu has no anemometer reading in its %.0f s window",
                        static_cast<unsigned long>(c.clip.sequence), c.label.window);
    auto msg = boost::make_shared<clothwind::Clip>(ros_bridge::ToClipMsg(c, frame_id_, wind_frame_.frame_id()));
    if (preview_pub_.getNumSubscribers() > 0) {
      const auto& middle = c.clip.frames[c.clip.frames.size() / 2];
      std_msgs::Header h = msg->header;
      h.stamp = ros::Time(middle.stamp);
      preview_pub_.publish(ros_bridge::ClipFrameImageMsg(middle.image, h));
    }
    clip_pub_.publish(msg);
    Record(c);
  }

  static constexpr double kLatestStamp = 4294967295.0 - 3600.0;  // [s] ROS time's end, less an hour

  // Queues a clip for the recording (a full queue is counted by the writer, reported by OnTimer).
  void Record(const sensors::LabelledClip& c) {
    UpdateSource();
    recording_->Record(c, source_);
  }

  // The frames the recorded clips are in, as last known.
  void UpdateSource() {
    source_.frame_id = frame_id_;
    source_.wind_frame_id = wind_frame_.frame_id();
  }

  // The clock to check stamps against; none while simulated time has not started.
  static double Now() {
    const ros::Time now = ros::Time::now();
    return now.isZero() ? sensors::kNoClock : now.toSec();
  }

  void NoteError(const std::string& what) {
    ++errors_;
    last_error_ = what;
    last_error_time_ = ros::SteadyTime::now();
    WALL_ERROR_THROTTLE(5.0, "clip_buffer: %s", what.c_str());
  }

  double SecondsSince(const ros::SteadyTime& t) const { return t.isZero() ? 1e9 : (ros::SteadyTime::now() - t).toSec(); }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    using diagnostic_msgs::DiagnosticStatus;
    const auto& s = pipeline_->stats();
    stat.summary(DiagnosticStatus::OK, "making clips");
    // Each condition adds itself; the worst level wins and the messages are joined.
    if (!recording_->error().empty()) stat.mergeSummary(DiagnosticStatus::ERROR, "not recording: " + recording_->error());
    // An error holds the ERROR for kErrorHold s, then stays in "last error" only: one bad frame an
    // hour ago is not a fault now.
    if (SecondsSince(last_error_time_) < kErrorHold) stat.mergeSummary(DiagnosticStatus::ERROR, last_error_);
    if (s.frames_in == 0) stat.mergeSummary(DiagnosticStatus::WARN, "no camera frames yet");
    // Frames that stopped coming (a bag ended or paused, the camera node gone): it stayed OK
    // "making clips" for ever.
    const double idle = SecondsSince(last_image_);
    if (s.frames_in > 0 && idle > std::max(2.0, flush_after_))
      stat.mergeSummaryf(DiagnosticStatus::WARN,
                         "no camera frames for %.0f s (a recording ended or paused, or the camera stopped)", idle);
    // Frames arriving and no clip made: stamps that do not increase, or a camera too slow for
    // gap_tolerance (both used to stay OK). Counted from the last report that saw a new clip.
    if (s.clips_made != stall_base_.clips_made) stall_base_ = s;
    const std::string stalled = sensors::ClipStallReason(stall_base_, s, pipeline_->options());
    if (!stalled.empty()) stat.mergeSummary(DiagnosticStatus::WARN, stalled);
    // Frames repeated by the resampler, over windows of 10 s (the last window's verdict shown).
    const double wall = ros::SteadyTime::now().toSec();
    if (wall - repeat_base_wall_ >= 10.0) {
      repeat_reason_ = sensors::ClipRepeatReason(repeat_base_, s, pipeline_->options());
      loss_reason_ = sensors::ClipLossReason(repeat_base_, s, pipeline_->options());
      repeat_base_ = s;
      repeat_base_wall_ = wall;
    }
    if (!repeat_reason_.empty()) stat.mergeSummary(DiagnosticStatus::WARN, repeat_reason_);
    if (!loss_reason_.empty()) stat.mergeSummary(DiagnosticStatus::WARN, loss_reason_);
    if (s.unlabelled_run > 0)
      stat.mergeSummaryf(DiagnosticStatus::WARN, "the last %lu clip(s) have no anemometer reading in their %.0f s window",
                         static_cast<unsigned long>(s.unlabelled_run), pipeline_->options().label_window);
    if (SecondsSince(last_future_) < kErrorHold)
      stat.mergeSummaryf(DiagnosticStatus::WARN, "stamps %.1f s after the clock refused (a clock set wrong?)",
                         s.last_future_lead);
    if (s.frames_in > 0 && frame_id_.empty())
      stat.mergeSummary(DiagnosticStatus::WARN, "clips have no frame_id (set ~frame_id or the camera's header.frame_id)");
    stat.add("encoding", sensors::ClipFrameEncoding(pipeline_->options().colour));
    stat.add("frame_id", frame_id_);
    stat.add("frames in", s.frames_in);
    stat.add("frames dropped", s.frames_dropped);
    stat.add("frames stamped in the future", s.frames_future);
    stat.add("frames of the previous pass dropped (after the clock went back)", s.frames_previous_pass);
    stat.add("readings of the previous pass dropped (after the clock went back)", s.readings_previous_pass);
    stat.add("frames stamped back in time (dropped)", s.frames_stale);
    stat.add("frames out (25 fps)", s.frames_out);
    stat.add("gaps", s.gaps);
    stat.add("frames out thrown away with clips a gap broke", s.frames_discarded);
    stat.add("last gap [s]", s.last_gap);
    stat.add("time jumps back", s.time_jumps);
    stat.add("clips labelled at a time jump", s.clips_at_jumps);
    stat.add("clips made", s.clips_made);
    stat.add("clips published", s.clips_released);
    stat.add("clips without label", s.clips_unlabelled);
    stat.add("clips waiting for label", pipeline_->pending());
    stat.add("readings in", s.readings_in);
    stat.add("readings too late", s.readings_late);
    stat.add("readings stamped in the future", s.readings_future);
    stat.add("wind direction frame", wind_frame_.frame_id());
    stat.add("directions in another frame (left out)", wind_frame_.rejected());
    if (wind_frame_.rejected() > 0)
      stat.add("last other direction frame", wind_frame_.last_rejected_frame());
    stat.add("record folder", record_dir_.empty() ? "(not recording)" : record_dir_);
    const auto r = recording_->tally();
    stat.add("clips recorded", r.recorded);
    stat.add("clips not recorded", r.not_recorded);
    stat.add("clips waiting to be written", r.waiting);
    stat.add("clips not yet in index.json", r.unlisted);
    stat.addf("slowest clip write [s]", "%.3f", r.max_write_s);
    stat.add("errors", errors_);
    stat.add("last error", last_error_.empty() ? "(none)" : last_error_);
    stat.add("last error age [s]", last_error_.empty() ? 0.0 : SecondsSince(last_error_time_));
  }

  static constexpr double kErrorHold = 10.0;   // [s] wall
  static constexpr double kShutdownBudget = 12.0;  // [s] wall, within roslaunch's 15 s before SIGTERM

  ros::NodeHandle nh_;
  std::mutex mutex_;
  std::unique_ptr<sensors::ClipPipeline> pipeline_;
  sensors::ClipPipelineStats stall_base_;  // the counters when a clip was last seen made
  sensors::ClipPipelineStats repeat_base_;  // the counters at the start of the repeat window
  double repeat_base_wall_ = 0;             // its wall time [s]
  std::string repeat_reason_;               // ClipRepeatReason of the last whole window
  std::string loss_reason_;                 // ClipLossReason of the same window
  std::unique_ptr<sensors::ClipRecording> recording_;  // ~record_dir's folder
  sensors::ClipSourceInfo source_;
  std::string frame_id_;
  bool frame_id_from_msg_ = false;
  sensors::WindDirectionFrameGate wind_frame_;
  double flush_after_ = 3.0;
  ros::SteadyTime last_input_;
  ros::SteadyTime last_image_;  // the last camera frame's arrival
  std::string record_dir_;
  int jpeg_quality_ = 95;
  double index_interval_ = 30.0;  // [s] see sensors::DatasetWriter
  std::string last_error_;
  ros::SteadyTime last_error_time_, last_future_;
  uint64_t errors_ = 0;
  ros::Publisher clip_pub_, preview_pub_;
  ros::Subscriber image_sub_, info_sub_, wind_sub_;
  ros::SteadyTimer flush_timer_;
  diagnostic_updater::Updater updater_;
  ros_bridge::WallThrottle diagnostics_throttle_;
  double diagnostic_period_ = ros_bridge::DiagnosticPeriod(updater_);  // after updater_, which reads it
};

}  // namespace
}  // namespace clothwind

int main(int argc, char** argv) {
  ros::init(argc, argv, "clip_buffer");
  // SIGTERM (systemd, docker stop, roslaunch's escalation) ends the spin like SIGINT, so the
  // clips still waiting are labelled and recorded rather than lost with the process.
  std::signal(SIGTERM, [](int) { ros::requestShutdown(); });
  ros::NodeHandle nh, pnh("~");
  clothwind::ros_bridge::StrictParams params(pnh);
  try {
    clothwind::ros_bridge::CheckDiagnosticPeriod(params);  // before the node's diagnostic_updater reads it
    clothwind::ClipBufferNode node(nh, params);
    params.WarnUnread("clip_buffer");
    ros::spin();
    // A second Ctrl-C (or SIGTERM) ends the process at once, the clips not yet written lost: what
    // is on disk is whole and listed (each clip lands under a temporary name, then is renamed and
    // listed). roscpp's handler only asked again for the shutdown already under way, so a hung
    // disk left the node to `kill -9`.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    node.Finish();
  } catch (const std::exception& e) {
    clothwind::ros_bridge::RosFatal(std::string("clip_buffer: ") + e.what());
    return 1;
  }
  return 0;
}
