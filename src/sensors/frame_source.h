#ifndef CLOTHWIND_SENSORS_FRAME_SOURCE_H_
#define CLOTHWIND_SENSORS_FRAME_SOURCE_H_

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include <opencv2/core/mat.hpp>

#include "sensors/frame_timestamp.h"

namespace clothwind {
namespace sensors {

// Severity of a message a source reports (the node maps these to ROS_INFO/WARN/ERROR).
enum class LogLevel { kInfo, kWarn, kError };

// Where sources report what they negotiated or why they failed. May be empty (messages dropped).
using LogFn = std::function<void(LogLevel level, const std::string& message)>;

// One captured frame.
struct Frame {
  cv::Mat image;          // height by width, CV_8UC1 (encoding mono8) or CV_8UC3 BGR (bgr8)
  std::string encoding;   // "mono8" or "bgr8" (ROS sensor_msgs/image_encodings names)
  int64_t stamp_ns = 0;   // capture instant in ROS time [ns since the Unix epoch]
  uint64_t sequence = 0;  // source frame counter (driver sequence for V4L2, index otherwise)
};

// What a Read produced.
enum class ReadStatus {
  kFrame,     // *frame holds a new frame
  kNoFrame,   // nothing within the wait (not an error: call again)
  kEnd,       // the source is exhausted (a file/folder without loop); no more frames will come
  kBadFrame,  // a frame came but could not be read (flagged corrupt by the driver, would not
              // decode, another size); error() says why. The source goes on with the next.
  kError,     // the source failed (device lost, a reopen failed, a recording no longer
              // readable); error() says why. V4L2 recovers by itself on later Reads.
};

// A camera or a recording behind one interface, so the node and the rest of the pipeline do not
// care whether frames come from a V4L2 device, a video file or a folder of images.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // Opens the source. Returns false (and error() says why) on failure; may be retried.
  virtual bool Open() = 0;

  // Waits up to max_wait_s [s] for the next frame.
  // Outputs:
  //   frame  the frame when kFrame is returned
  virtual ReadStatus Read(Frame* frame, double max_wait_s) = 0;

  // Releases the source (idempotent).
  virtual void Close() = 0;

  // True between a successful Open and Close. A V4L2 camera stays "open" while it is
  // reconnecting (it heals itself); a recording closes itself when nothing in it is readable any
  // more, and then needs Open again.
  virtual bool IsOpen() const = 0;

  // Last error message ("" when none).
  virtual std::string error() const = 0;

  // Human-readable description of the source, e.g. "/dev/video0 640x480 YUYV @30 fps".
  virtual std::string Describe() const = 0;

  // Nominal frame rate [Hz] (negotiated for cameras, native for recordings); 0 if unknown.
  virtual double NominalRate() const = 0;

  // Key/value status for diagnostics (state, negotiated format, drops, ...).
  virtual std::map<std::string, std::string> Status() const = 0;
};

// Paces a recording at its native rate: frame k is due at start + k / rate. The due instant,
// mapped to ROS time, is the frame's stamp, so stamps are evenly spaced even if a read is late.
// Paced on the monotonic clock; under simulated ROS time (Clock::RosTimeIsSimulated) on ROS time
// itself, so frames follow a replay's /clock when it runs slower (rosbag play -r 0.5), pauses or
// loops, and none comes before /clock has started (ROS time 0). Paced on the wall clock, stamps
// drifted ahead of a slowed replay until the clip buffer refused them as from the future.
class FramePacer {
 public:
  // Inputs:
  //   clock    clocks (not owned)
  //   rate_hz  frames per second (> 0)
  FramePacer(Clock* clock, double rate_hz);

  // Restarts the schedule: the next frame is due now.
  void Restart();

  // Waits until the next frame is due, but at most max_wait_s [s].
  // Outputs:
  //   stamp_ns  ROS time the frame is due [ns] (valid when true is returned)
  // Returns true when the frame is due (then the schedule advances by one frame).
  bool WaitNext(double max_wait_s, int64_t* stamp_ns);

  double rate_hz() const { return rate_hz_; }

 private:
  Clock* clock_;
  double rate_hz_;
  bool started_ = false;
  int64_t start_pace_ns_ = 0;  // the schedule's start on the pacing clock (see WaitNext)
  int64_t start_ros_ns_ = 0;
  int64_t index_ = 0;
};

// A recording's next frame, read ahead of its due instant, or an unreadable one that keeps its
// slot in time (and its sequence number, as a camera's lost frame does): it is reported when its
// frame was due, so the frame after it keeps its own slot's stamp. Taking neither stamped the
// frames after it one period early: 31 intervals in a 30-slot clip read every frequency 3 % high.
class PacedFrameSlot {
 public:
  // True when nothing waits: the source reads the next frame.
  bool empty() const { return !frame_valid_ && !bad_; }
  // A frame read (its sequence set, its stamp not yet).
  void Fill(Frame frame);
  // An unreadable frame.
  void FillBad();
  void Clear();
  // Waits until the slot's frame is due, but at most max_wait_s [s] (see FramePacer::WaitNext).
  // Outputs:
  //   frame  the frame, stamped with its due instant (only when kFrame is returned)
  // Returns kNoFrame while not yet due (the slot stays filled), then kBadFrame for an unreadable
  // frame or kFrame; either empties the slot.
  ReadStatus ReleaseWhenDue(FramePacer* pacer, double max_wait_s, Frame* frame);

 private:
  bool frame_valid_ = false;
  bool bad_ = false;
  Frame frame_;
};

// Options to build any FrameSource (the node's parameters).
struct FrameSourceOptions {
  std::string source = "v4l2";  // "v4l2", "video" or "folder"
  std::string path;             // device (/dev/video0), video file or image folder
  // V4L2
  std::string pixel_format = "YUYV";
  int width = 640;     // [px]
  int height = 480;    // [px]
  double fps = 30.0;   // [Hz]; also the rate of a folder, and of a video whose file has none
  int buffers = 4;
  double timeout_s = 2.0;  // no frame for this long: the device is considered lost and reopened
  int auto_exposure = -1;         // -1 leave, 0 manual, 1 automatic
  int exposure_absolute = -1;     // [100 us] (V4L2 unit); -1 leave
  int gain = -1;                  // device units; -1 leave
  // Recordings
  bool loop = false;
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_FRAME_SOURCE_H_
