#ifndef CLOTHWIND_SENSORS_V4L2_CAMERA_H_
#define CLOTHWIND_SENSORS_V4L2_CAMERA_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sensors/frame_source.h"
#include "sensors/frame_timestamp.h"
#include "sensors/pixel_format.h"
#include "sensors/v4l2_io.h"

namespace clothwind {
namespace sensors {

// What the user asks of a V4L2 camera. The driver may give something else (V4l2Negotiated).
struct V4l2Options {
  std::string device = "/dev/video0";
  PixelFormat format = PixelFormat::kYuyv;
  int width = 640;        // [px]
  int height = 480;       // [px]
  double fps = 30.0;      // [Hz]
  int buffers = 4;        // mmap buffers to request (the driver may grant another count, >= 2)
  double timeout_s = 2.0; // no frame for this long (at least 5 frame periods, and 5 manual
                          // exposures): device lost, reopened
  int auto_exposure = -1;      // -1 leave as is, 0 manual, 1 automatic
  int exposure_absolute = -1;  // V4L2_CID_EXPOSURE_ABSOLUTE [100 us]; -1 leave (>= 0 implies manual)
  int gain = -1;               // V4L2_CID_GAIN [device units]; -1 leave
  double backoff_initial_s = 0.25;  // first reopen delay after a loss [s]; doubles per failure
  double backoff_max_s = 8.0;       // reopen delay cap [s]
  int offset_window = 100;          // frames the clock-offset minimum is taken over
};

// What the driver agreed to.
struct V4l2Negotiated {
  PixelFormat format = PixelFormat::kYuyv;
  uint32_t fourcc = 0;
  int width = 0;            // [px]
  int height = 0;           // [px]
  int bytes_per_line = 0;   // row stride [bytes] (0 for compressed formats)
  uint32_t size_image = 0;  // buffer size [bytes]
  double fps = 0;           // [Hz]; 0 if the driver does not say
  int buffers = 0;          // mmap buffers granted
  std::string driver, card, bus;  // VIDIOC_QUERYCAP strings
  // Exposure as the driver holds it after the controls were applied (VIDIOC_G_CTRL):
  int exposure_auto = -1;   // V4L2_CID_EXPOSURE_AUTO's value; -1 when the camera has no such control
  double exposure_s = 0;    // fixed exposure time [s] (manual or shutter priority); 0 when automatic or not readable
};

// Counters for diagnostics.
struct V4l2Stats {
  uint64_t frames = 0;       // frames delivered
  uint64_t drops = 0;        // frames lost, from gaps in v4l2_buffer.sequence
  uint64_t corrupt = 0;      // buffers flagged V4L2_BUF_FLAG_ERROR or that failed to convert
  uint64_t reconnects = 0;   // successful reopens after a loss
  uint64_t losses = 0;       // times the device was lost (ENODEV/EIO/..., poll error, timeout)
  uint64_t timeouts = 0;     // losses due to no frame within timeout_s
  uint64_t open_failures = 0;
};

// Streaming V4L2 capture with mmap buffers (QUERYCAP, S_FMT/G_FMT, S_PARM/G_PARM,
// QUERYCTRL/S_CTRL, REQBUFS, QUERYBUF, mmap, QBUF/DQBUF, STREAMON/OFF, poll), frames converted
// to mono8/bgr8 and stamped with the driver's capture time mapped to ROS time
// (FrameTimestamper). A device that fails (ENODEV/EIO from an ioctl, a poll error, or no frame
// within timeout_s) is released and reopened by later Reads with exponential backoff, so
// unplugging and replugging the camera only costs the frames in between.
class V4l2Camera : public FrameSource {
 public:
  // Inputs:
  //   options  what to ask the driver
  //   io       system calls (not owned; SyscallV4l2Io or a fake)
  //   clock    clocks (not owned)
  //   log      where negotiation results and failures are reported (may be empty)
  V4l2Camera(V4l2Options options, V4l2Io* io, Clock* clock, LogFn log = {});
  ~V4l2Camera() override;

  // Opens, negotiates, maps buffers and starts streaming. On failure error() says why; calling
  // Read afterwards keeps retrying with backoff.
  bool Open() override;

  // Waits up to max_wait_s for a frame; while the device is lost, waits for the next reopen
  // attempt (returns kNoFrame, or kError when an attempt failed).
  ReadStatus Read(Frame* frame, double max_wait_s) override;

  // STREAMOFF, munmap, close. Reads after Close reopen the device.
  void Close() override;

  // True from Open (even a failed one: Reads keep retrying) until Close.
  bool IsOpen() const override { return state_ != "closed"; }

  std::string error() const override { return error_; }
  std::string Describe() const override;
  double NominalRate() const override { return negotiated_.fps > 0 ? negotiated_.fps : options_.fps; }
  std::map<std::string, std::string> Status() const override;

  bool streaming() const { return fd_ >= 0 && streaming_; }
  const V4l2Negotiated& negotiated() const { return negotiated_; }
  const V4l2Stats& stats() const { return stats_; }
  // Delay before the next reopen attempt [s] (current backoff step).
  double backoff_s() const { return backoff_s_; }
  // Current ROS - monotonic clock offset estimate [ns].
  int64_t clock_offset_ns() const { return stamper_.OffsetNs(); }

 private:
  struct Buffer {
    void* start = nullptr;
    size_t length = 0;
  };

  bool OpenDevice();                      // one attempt; releases everything on failure
  bool NegotiateFormat();
  void NegotiateFrameRate();
  void ApplyControls();
  // Reads back the exposure mode and, when manual, its time into negotiated_; WARNs when one
  // exposure outlasts a frame period (the camera then delivers fewer frames than negotiated).
  void ReadBackExposure();
  // No frame for this long [s] means the device is lost: ~timeout, but at least 5 frame
  // periods and 5 manual exposures (a long exposure at dusk is a slow camera, not a dead one).
  double LossTimeout() const;
  void SetControl(uint32_t id, const char* name, int value);
  bool SetupBuffers();
  void ReleaseDevice();                   // STREAMOFF, munmap, close; ignores errors
  void Lost(const std::string& why);      // release and schedule a reopen
  // Why the loss deadline passed: "no frame for T s", or "no good frame …" when frames came
  // since the last good one but none could be read.
  std::string NoGoodFrameText(double timeout_s) const;
  std::string ListDeviceFormats();
  bool Fail(const std::string& why);      // sets error_, returns false
  void Log(LogLevel level, const std::string& message);

  V4l2Options options_;
  V4l2Io* io_;
  Clock* clock_;
  LogFn log_;
  FrameTimestamper stamper_;

  int fd_ = -1;
  bool streaming_ = false;
  std::vector<Buffer> buffers_;
  V4l2Negotiated negotiated_;
  V4l2Stats stats_;
  std::string state_ = "closed";
  std::string error_;

  bool ever_opened_ = false;
  bool have_sequence_ = false;
  uint32_t last_sequence_ = 0;
  int64_t last_frame_mono_ns_ = 0;  // when the last good frame was read (or the device opened)
  uint64_t corrupt_at_last_good_ = 0;  // stats_.corrupt then: more now means frames came, none good
  int64_t next_attempt_mono_ns_ = 0;
  double backoff_s_ = 0;
};

// Formats a V4L2 negotiation for logs, e.g. "640x480 YUYV @30 fps, 4 buffers".
std::string DescribeNegotiated(const V4l2Negotiated& n);
// "manual 0.0150 s", "shutter priority 0.0100 s", "auto (mode 3)", or "unknown (no exposure control)".
std::string DescribeExposure(const V4l2Negotiated& n);

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_V4L2_CAMERA_H_
