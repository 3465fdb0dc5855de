// clip_buffer_node: camera frames + anemometer readings in, labelled 25 fps clips out.
//
// Subscribes  camera/image_raw (sensor_msgs/Image), camera/camera_info (kept for recorded
//             clips' metadata), anemometer/wind (clothwind/WindMeasurement)
// Publishes   clips (clothwind/Clip), clips/preview (sensor_msgs/Image mono8, or bgr8 with
//             ~colour: the latest clip's middle frame, only built while someone subscribes),
//             /diagnostics
// All the logic is in sensors::ClipPipeline and sensors::DatasetWriter (see docs/clips.md); clips
// are recorded on a thread of their own (sensors::AsyncDatasetWriter), so a slow disk never holds
// up the camera callback.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <clothwind/Clip.h>
#include <clothwind/WindMeasurement.h>

#include "common/formatted.h"
#include "ros_bridge/clip_conversions.h"
#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "ros_bridge/wall_throttle.h"
#include "sensors/async_dataset_writer.h"
#include "sensors/clip_pipeline.h"
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
    OpenRecording();

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

  ~ClipBufferNode() {
    if (closer_.joinable()) closer_.join();
  }

  // Opens record_dir_ (when set and not open yet); on failure keeps why for the diagnostics.
  void OpenRecording() {
    if (record_dir_.empty() || writer_) return;
    last_open_attempt_ = ros::SteadyTime::now();
    try {
      writer_ = std::make_unique<sensors::AsyncDatasetWriter>(
          std::make_unique<sensors::DatasetWriter>(record_dir_, jpeg_quality_, index_interval_), kRecordQueue);
      if (!recording_error_.empty()) ROS_INFO("clip_buffer: recording works again");
      recording_error_.clear();
      record_dir_mounted_ = sensors::IsMountPoint(record_dir_);
      ROS_INFO("clip_buffer: recording clips to %s (%zu already there%s)", record_dir_.c_str(),
               writer_->size_at_open(),
               writer_->recovered() > 0
                   ? (", " + std::to_string(writer_->recovered()) + " leftovers of an earlier run cleared").c_str()
                   : "");
    } catch (const std::exception& e) {
      if (recording_error_ != e.what())
        ROS_ERROR("clip_buffer: not recording (publishing clips still; retrying every %.0f s): %s", kReopenEvery,
                  e.what());
      recording_error_ = e.what();
    }
  }

  // Labels and records whatever is still waiting (called on shutdown; nothing is published then).
  // The last clips wait for room in the writer's queue (a full queue of a slow disk dropped them
  // with no report after), for kShutdownBudget s at most: roslaunch sends SIGTERM 15 s after
  // Ctrl-C and SIGKILL 2 s later, and a kill mid-way lost the clips on disk since the last
  // index rewrite with no word (the writer now lists each clip as it lands). Clips given up are
  // named, and the tally, with the last write or index error, is said at the end.
  void Finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    // (A lost folder's writer still closing is joined by the destructor, after the last clips: a
    // yanked disk's write can hang past roslaunch's SIGKILL.)
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                               std::chrono::duration<double>(kShutdownBudget));
    std::vector<std::string> abandoned;
    const auto waiting = pipeline_->Flush();
    if (writer_ && (!waiting.empty() || writer_->stats().queued > 0))
      ROS_INFO("clip_buffer: recording the last %zu clips into %s (at most %.0f s)",
               waiting.size() + writer_->stats().queued, writer_->root().c_str(), kShutdownBudget);
    for (const auto& c : waiting) Record(c, deadline, &abandoned);
    if (!writer_) {
      if (not_recorded_ > 0)
        ROS_WARN("clip_buffer: %llu clips not recorded (no recording folder open: %s)",
                 static_cast<unsigned long long>(not_recorded_), recording_error_.c_str());
      if (written_before_ + failed_before_ + dropped_before_ > 0)
        ROS_INFO("clip_buffer: recording into %s ends with its folder lost: %llu clips written, %llu failed, "
                 "%llu dropped (queue full) before",
                 record_dir_.c_str(), static_cast<unsigned long long>(written_before_),
                 static_cast<unsigned long long>(failed_before_), static_cast<unsigned long long>(dropped_before_));
      return;
    }
    writer_->DrainBy(deadline, &abandoned);
    const auto s = writer_->stats();
    if (!abandoned.empty())
      ROS_ERROR("clip_buffer: %zu clips not recorded: the disk did not write them within %.0f s of shutdown "
                "(roslaunch kills a node 17 s after Ctrl-C): %s",
                abandoned.size(), kShutdownBudget, JoinNames(abandoned).c_str());
    if (s.failed > 0) ROS_ERROR("clip_buffer: last failed clip write: %s", s.last_error.c_str());
    if (!s.index_error.empty()) ROS_ERROR("clip_buffer: index.json not rewritten: %s", s.index_error.c_str());
    ROS_INFO("clip_buffer: recording into %s ends: %llu clips written, %llu failed, %llu dropped (queue full), "
             "%zu given up at shutdown, %llu not recorded (no folder open)",
             writer_->root().c_str(), static_cast<unsigned long long>(written_before_ + s.written),
             static_cast<unsigned long long>(failed_before_ + s.failed),
             static_cast<unsigned long long>(dropped_before_ + s.dropped), abandoned.size(),
             static_cast<unsigned long long>(not_recorded_));
  }

 private:
  void OnImage(const sensor_msgs::ImageConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_input_ = ros::SteadyTime::now();
    last_image_ = last_input_;
    index_flush_asked_ = false;
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
    index_flush_asked_ = false;
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
    if (!writer_) return;
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
    // The folder lost (a disk unplugged, or replugged and mounted again): the writer refused every
    // later clip until the node restarted. It is closed and the folder reopened once it is back;
    // not created again, so clips never land on a bare mount point.
    if (writer_) {
      if (const std::string lost = writer_->FolderLost(); !lost.empty()) {
        NoteError(lost + "; reopening it every " + std::to_string(static_cast<int>(kReopenEvery)) + " s once it is there");
        // Its tally kept, its queued clips counted as not recorded; closed off this thread, as
        // closing waits for the clip being written (seconds on a slow card), which held the
        // camera callbacks and broke the clips being published.
        const auto r = writer_->stats();
        written_before_ += r.written;
        failed_before_ += r.failed;
        dropped_before_ += r.dropped;
        not_recorded_ += r.queued;
        failed_seen_ = dropped_seen_ = 0;
        index_error_seen_.clear();
        if (closer_.joinable()) closer_.join();  // done: no reopen before it closed (below)
        closer_closed_ = false;
        closer_ = std::thread([this, lost_writer = std::move(writer_)]() mutable {
          lost_writer.reset();
          closer_closed_ = true;
        });
        folder_lost_ = true;
        recording_error_ = lost;
        last_open_attempt_ = ros::SteadyTime::now();
      }
    }
    if (!writer_ && !record_dir_.empty() && (ros::SteadyTime::now() - last_open_attempt_).toSec() >= kReopenEvery) {
      std::error_code ec;
      if (!closer_closed_) {
        // The lost writer still finishing its clip: two writers in one path would each rewrite
        // the index from their own list.
        last_open_attempt_ = ros::SteadyTime::now();
      } else if (folder_lost_ && !std::filesystem::is_directory(record_dir_, ec)) {
        last_open_attempt_ = ros::SteadyTime::now();
        recording_error_ = "the recording folder " + record_dir_ + " is gone; waiting for it to come back";
      } else if (folder_lost_ && record_dir_mounted_ && !sensors::IsMountPoint(record_dir_)) {
        // A disk was mounted there: its bare mount point (an fstab entry) is not the disk.
        last_open_attempt_ = ros::SteadyTime::now();
        recording_error_ = "the disk mounted at " + record_dir_ + " is not there; waiting for it to come back";
      } else {
        OpenRecording();
      }
    }
    // Input stopped (a replay ended, the camera paused): list the clips recorded since the last
    // index rewrite now rather than after ~index_interval (after the clips just flushed).
    if (writer_ && !index_flush_asked_ && (ros::SteadyTime::now() - last_input_).toSec() > flush_after_) {
      writer_->RequestIndexFlush();
      index_flush_asked_ = true;
    }
    if (writer_) {  // the recording thread's failures, reported from here
      const auto r = writer_->stats();
      if (r.failed > failed_seen_) NoteError("recording failed: " + r.last_error);
      if (r.dropped > dropped_seen_)
        NoteError("recording too slow: " + std::to_string(r.dropped - dropped_seen_) +
                  " clip(s) not recorded (queue of " + std::to_string(kRecordQueue) + " full)");
      failed_seen_ = r.failed;
      dropped_seen_ = r.dropped;
      if (!r.index_error.empty() && r.index_error != index_error_seen_)
        NoteError("index.json not rewritten (the clips are in place; the next rewrite or the next "
                  "opening of the folder lists them): " + r.index_error);
      index_error_seen_ = r.index_error;
    }
    // force_update once a wall second: Updater::update() waits for ROS time, which stands still
    // while a bag is paused and jumps back when it loops. (WallThrottle: again at once after the
    // wall clock steps back, which held every report until it caught up.)
    if (diagnostics_throttle_.Due(diagnostic_period_)) updater_.force_update();
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
  // At shutdown (`abandoned` given) it waits for room until `deadline`, and a clip that finds none
  // is named in *abandoned.
  void Record(const sensors::LabelledClip& c,
              std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point(),
              std::vector<std::string>* abandoned = nullptr) {
    if (record_dir_.empty()) return;
    if (!writer_) {
      ++not_recorded_;
      return;
    }
    source_.frame_id = frame_id_;
    source_.wind_frame_id = wind_frame_.frame_id();
    if (!abandoned) {
      writer_->Enqueue(c, source_);
    } else if (!writer_->Enqueue(c, source_, deadline) && !c.clip.frames.empty()) {
      abandoned->push_back(sensors::ClipFolderName(c.clip.frames.front().stamp));
    }
  }

  // "a, b, c" or "a, b, ... (n more), z": the log line stays readable with hundreds of clips.
  static std::string JoinNames(const std::vector<std::string>& names) {
    std::string out;
    const size_t shown = names.size() <= 6 ? names.size() : 4;
    for (size_t i = 0; i < shown; ++i) out += (i ? ", " : "") + names[i];
    if (shown < names.size())
      out += ", ... (" + std::to_string(names.size() - shown - 1) + " more), " + names.back();
    return out;
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
    if (!recording_error_.empty()) stat.mergeSummary(DiagnosticStatus::ERROR, "not recording: " + recording_error_);
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
    const auto r = writer_ ? writer_->stats() : sensors::AsyncDatasetWriter::Stats();
    stat.add("clips recorded", written_before_ + r.written);
    stat.add("clips not recorded", not_recorded_ + failed_before_ + dropped_before_ + r.failed + r.dropped);
    stat.add("clips waiting to be written", r.queued);
    stat.add("clips not yet in index.json", r.unlisted);
    stat.addf("slowest clip write [s]", "%.3f", r.max_write_s);
    stat.add("errors", errors_);
    stat.add("last error", last_error_.empty() ? "(none)" : last_error_);
    stat.add("last error age [s]", last_error_.empty() ? 0.0 : SecondsSince(last_error_time_));
  }

  static constexpr double kErrorHold = 10.0;   // [s] wall
  static constexpr double kReopenEvery = 10.0; // [s] wall
  static constexpr double kShutdownBudget = 12.0;  // [s] wall, within roslaunch's 15 s before SIGTERM
  static constexpr size_t kRecordQueue = 16;   // clips (16 x 30 x 300^2 B = 43 MB of mono8 at most)

  ros::NodeHandle nh_;
  std::mutex mutex_;
  std::unique_ptr<sensors::ClipPipeline> pipeline_;
  sensors::ClipPipelineStats stall_base_;  // the counters when a clip was last seen made
  sensors::ClipPipelineStats repeat_base_;  // the counters at the start of the repeat window
  double repeat_base_wall_ = 0;             // its wall time [s]
  std::string repeat_reason_;               // ClipRepeatReason of the last whole window
  std::string loss_reason_;                 // ClipLossReason of the same window
  std::unique_ptr<sensors::AsyncDatasetWriter> writer_;
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
  std::string index_error_seen_;
  bool index_flush_asked_ = false;  // since the last input
  std::string recording_error_;  // why record_dir_ is not open; empty when it is (or not set)
  bool folder_lost_ = false;     // it was open and went: reopened only once it exists again
  bool record_dir_mounted_ = false;  // record_dir_ was a mount point when it was opened
  std::thread closer_;               // closes a lost folder's writer off the spinner thread
  std::atomic<bool> closer_closed_{true};  // it has (no writer closing now)
  uint64_t written_before_ = 0, failed_before_ = 0, dropped_before_ = 0;  // lost writers' tallies
  ros::SteadyTime last_open_attempt_;
  std::string last_error_;
  ros::SteadyTime last_error_time_, last_future_;
  uint64_t errors_ = 0;
  uint64_t not_recorded_ = 0, failed_seen_ = 0, dropped_seen_ = 0;
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
    clothwind::ClipBufferNode node(nh, params);
    params.Known("diagnostic_period");  // read by diagnostic_updater: the wall timer's period (ros_bridge/wall_diagnostics.h)
    params.WarnUnread("clip_buffer");
    ros::spin();
    node.Finish();
  } catch (const std::exception& e) {
    ROS_FATAL("clip_buffer: %s", e.what());
    return 1;
  }
  return 0;
}
