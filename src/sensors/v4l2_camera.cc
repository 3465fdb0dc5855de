#include "sensors/v4l2_camera.h"

#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>

namespace clothwind {
namespace sensors {
namespace {

std::string ErrnoText(int err) { return std::string(std::strerror(err)) + " (errno " + std::to_string(err) + ")"; }

std::string FpsText(double fps) {
  std::ostringstream s;
  s.precision(4);
  s << fps;
  return s.str();
}

std::string CString(const uint8_t* bytes, size_t n) {
  return std::string(reinterpret_cast<const char*>(bytes), strnlen(reinterpret_cast<const char*>(bytes), n));
}

}  // namespace

std::string DescribeNegotiated(const V4l2Negotiated& n) {
  std::ostringstream s;
  s << n.width << "x" << n.height << " " << FourccToString(n.fourcc) << " @"
    << (n.fps > 0 ? FpsText(n.fps) : std::string("?")) << " fps, " << n.buffers << " buffers";
  return s.str();
}

std::string DescribeExposure(const V4l2Negotiated& n) {
  if (n.exposure_auto < 0) return "unknown (no exposure control)";
  const bool shutter = n.exposure_auto == V4L2_EXPOSURE_SHUTTER_PRIORITY;
  if (n.exposure_auto != V4L2_EXPOSURE_MANUAL && !shutter)
    return "auto (mode " + std::to_string(n.exposure_auto) + ")";
  const char* kind = shutter ? "shutter priority" : "manual";
  if (n.exposure_s <= 0) return std::string(kind) + " (time not readable)";
  char text[64];
  std::snprintf(text, sizeof text, "%s %.4f s", kind, n.exposure_s);
  return text;
}

V4l2Camera::V4l2Camera(V4l2Options options, V4l2Io* io, Clock* clock, LogFn log)
    : options_(std::move(options)), io_(io), clock_(clock), log_(std::move(log)),
      stamper_(clock, options_.offset_window), backoff_s_(options_.backoff_initial_s) {}

V4l2Camera::~V4l2Camera() { ReleaseDevice(); }

void V4l2Camera::Log(LogLevel level, const std::string& message) {
  if (log_) log_(level, message);
}

bool V4l2Camera::Fail(const std::string& why) {
  error_ = options_.device + ": " + why;
  return false;
}

bool V4l2Camera::Open() {
  ReleaseDevice();
  backoff_s_ = options_.backoff_initial_s;
  if (OpenDevice()) return true;
  ++stats_.open_failures;
  state_ = "waiting for device";
  next_attempt_mono_ns_ = clock_->MonotonicNs() + static_cast<int64_t>(backoff_s_ * 1e9);
  return false;
}

void V4l2Camera::Close() {
  ReleaseDevice();
  state_ = "closed";
}

bool V4l2Camera::OpenDevice() {
  ReleaseDevice();
  fd_ = io_->Open(options_.device);
  if (fd_ < 0) {
    const int err = errno;
    std::string hint;
    if (err == EACCES) hint = "; add the user to the 'video' group (sudo usermod -aG video $USER)";
    if (err == ENOENT) hint = "; is the camera plugged in? (v4l2-ctl --list-devices)";
    Fail("cannot open: " + ErrnoText(err) + hint);
    fd_ = -1;
    return false;
  }
  v4l2_capability cap{};
  if (io_->Ioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0) {
    const int err = errno;
    ReleaseDevice();
    return Fail("VIDIOC_QUERYCAP failed, not a V4L2 device? " + ErrnoText(err));
  }
  const uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  negotiated_.driver = CString(cap.driver, sizeof(cap.driver));
  negotiated_.card = CString(cap.card, sizeof(cap.card));
  negotiated_.bus = CString(cap.bus_info, sizeof(cap.bus_info));
  if (!(caps & V4L2_CAP_VIDEO_CAPTURE)) {
    ReleaseDevice();
    return Fail("'" + negotiated_.card + "' is not a video capture device (a metadata node? try "
                "another /dev/videoN)");
  }
  if (!(caps & V4L2_CAP_STREAMING)) {
    ReleaseDevice();
    return Fail("'" + negotiated_.card + "' does not support streaming I/O");
  }
  if (!NegotiateFormat()) {
    ReleaseDevice();
    return false;
  }
  NegotiateFrameRate();
  ApplyControls();
  ReadBackExposure();
  if (!SetupBuffers()) {
    ReleaseDevice();
    return false;
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_->Ioctl(fd_, VIDIOC_STREAMON, &type) < 0) {
    const int err = errno;
    ReleaseDevice();
    return Fail("VIDIOC_STREAMON failed: " + ErrnoText(err));
  }
  streaming_ = true;
  have_sequence_ = false;
  stamper_.Reset();
  last_frame_mono_ns_ = clock_->MonotonicNs();
  corrupt_at_last_good_ = stats_.corrupt;
  state_ = "streaming";
  error_.clear();
  Log(LogLevel::kInfo, "streaming " + options_.device + " ('" + negotiated_.card + "', " +
                           negotiated_.driver + ", " + negotiated_.bus + "): " +
                           DescribeNegotiated(negotiated_));
  ever_opened_ = true;
  return true;
}

std::string V4l2Camera::ListDeviceFormats() {
  std::string list;
  for (uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (io_->Ioctl(fd_, VIDIOC_ENUM_FMT, &d) < 0) break;
    if (!list.empty()) list += ", ";
    list += FourccToString(d.pixelformat);
    const std::string desc = CString(d.description, sizeof(d.description));
    if (!desc.empty()) list += " (" + desc + ")";
  }
  return list.empty() ? "none listed" : list;
}

bool V4l2Camera::NegotiateFormat() {
  v4l2_format fmt{};
  fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  fmt.fmt.pix.width = static_cast<uint32_t>(options_.width);
  fmt.fmt.pix.height = static_cast<uint32_t>(options_.height);
  fmt.fmt.pix.pixelformat = PixelFormatFourcc(options_.format);
  fmt.fmt.pix.field = V4L2_FIELD_ANY;
  // S_FMT adjusts the request to what the hardware can do; G_FMT reads back what is in effect.
  if (io_->Ioctl(fd_, VIDIOC_S_FMT, &fmt) < 0) {
    const int err = errno;
    return Fail("VIDIOC_S_FMT " + std::to_string(options_.width) + "x" +
                std::to_string(options_.height) + " " + PixelFormatName(options_.format) +
                " failed: " + ErrnoText(err) + "; formats offered: " + ListDeviceFormats());
  }
  if (io_->Ioctl(fd_, VIDIOC_G_FMT, &fmt) < 0) {
    const int err = errno;
    return Fail("VIDIOC_G_FMT failed: " + ErrnoText(err));
  }
  PixelFormat got;
  if (!PixelFormatFromFourcc(fmt.fmt.pix.pixelformat, &got)) {
    return Fail("asked for " + PixelFormatName(options_.format) + ", the driver offers " +
                FourccToString(fmt.fmt.pix.pixelformat) +
                " which this node cannot convert; formats offered: " + ListDeviceFormats() +
                " (set ~pixel_format to YUYV, MJPEG or GREY from that list)");
  }
  if (fmt.fmt.pix.width == 0 || fmt.fmt.pix.height == 0) {
    return Fail("the driver negotiated an empty image size");
  }
  negotiated_.format = got;
  negotiated_.fourcc = fmt.fmt.pix.pixelformat;
  negotiated_.width = static_cast<int>(fmt.fmt.pix.width);
  negotiated_.height = static_cast<int>(fmt.fmt.pix.height);
  negotiated_.bytes_per_line = static_cast<int>(fmt.fmt.pix.bytesperline);
  negotiated_.size_image = fmt.fmt.pix.sizeimage;
  if (got != options_.format) {
    Log(LogLevel::kWarn, options_.device + ": asked for pixel format " +
                             PixelFormatName(options_.format) + ", the driver gives " +
                             PixelFormatName(got));
  }
  if (negotiated_.width != options_.width || negotiated_.height != options_.height) {
    Log(LogLevel::kWarn, options_.device + ": asked for " + std::to_string(options_.width) + "x" +
                             std::to_string(options_.height) + ", the driver gives " +
                             std::to_string(negotiated_.width) + "x" +
                             std::to_string(negotiated_.height) +
                             " (v4l2-ctl --list-formats-ext lists the sizes)");
  }
  return true;
}

void V4l2Camera::NegotiateFrameRate() {
  v4l2_streamparm parm{};
  parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  const bool have_parm = io_->Ioctl(fd_, VIDIOC_G_PARM, &parm) >= 0;
  if (have_parm && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) && options_.fps > 0) {
    // Frame interval as a fraction: 1/30 for integer rates, 1000/29970 for 29.97.
    const bool integral = std::abs(options_.fps - std::round(options_.fps)) < 1e-6;
    parm.parm.capture.timeperframe.numerator = integral ? 1 : 1000;
    parm.parm.capture.timeperframe.denominator =
        static_cast<uint32_t>(std::lround(integral ? options_.fps : options_.fps * 1000.0));
    if (io_->Ioctl(fd_, VIDIOC_S_PARM, &parm) < 0) {
      Log(LogLevel::kWarn, options_.device + ": VIDIOC_S_PARM (" + FpsText(options_.fps) +
                               " fps) failed: " + ErrnoText(errno));
    }
    io_->Ioctl(fd_, VIDIOC_G_PARM, &parm);
  } else {
    Log(LogLevel::kWarn, options_.device + ": the driver does not let the frame rate be set; "
                                           "using its own");
  }
  const v4l2_fract tpf = parm.parm.capture.timeperframe;
  negotiated_.fps = (have_parm && tpf.numerator > 0 && tpf.denominator > 0)
                        ? static_cast<double>(tpf.denominator) / tpf.numerator
                        : 0.0;
  if (negotiated_.fps > 0 && std::abs(negotiated_.fps - options_.fps) > 0.005 * options_.fps) {
    Log(LogLevel::kWarn, options_.device + ": asked for " + FpsText(options_.fps) +
                             " fps, the driver gives " + FpsText(negotiated_.fps) + " fps");
  }
}

void V4l2Camera::SetControl(uint32_t id, const char* name, int value) {
  v4l2_queryctrl q{};
  q.id = id;
  if (io_->Ioctl(fd_, VIDIOC_QUERYCTRL, &q) < 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED)) {
    Log(LogLevel::kWarn, options_.device + " has no " + name + " control; skipped");
    return;
  }
  std::vector<int> candidates{value};
  if (id == V4L2_CID_EXPOSURE_AUTO && value != V4L2_EXPOSURE_MANUAL) {
    // "Automatic" is aperture priority on UVC cameras (they lack full auto), full auto elsewhere.
    candidates = {V4L2_EXPOSURE_APERTURE_PRIORITY, V4L2_EXPOSURE_AUTO};
  }
  bool tried = false;
  int last_errno = 0;
  for (const int c : candidates) {
    int v = c;
    if (q.type == V4L2_CTRL_TYPE_MENU) {
      if (v < q.minimum || v > q.maximum) continue;
    } else if (v < q.minimum || v > q.maximum) {
      v = std::clamp(v, q.minimum, q.maximum);
      Log(LogLevel::kWarn, options_.device + ": " + name + " " + std::to_string(c) +
                               " is outside [" + std::to_string(q.minimum) + ", " +
                               std::to_string(q.maximum) + "]; using " + std::to_string(v));
    }
    v4l2_control ctrl{};
    ctrl.id = id;
    ctrl.value = v;
    if (io_->Ioctl(fd_, VIDIOC_S_CTRL, &ctrl) == 0) {
      Log(LogLevel::kInfo, options_.device + ": " + name + " = " + std::to_string(v));
      return;
    }
    tried = true;
    last_errno = errno;
  }
  if (tried) {
    Log(LogLevel::kWarn, options_.device + ": setting " + name + " failed: " +
                             ErrnoText(last_errno) + "; skipped");
  } else {
    Log(LogLevel::kWarn, options_.device + ": " + name + " does not offer the wanted mode; skipped");
  }
}

void V4l2Camera::ApplyControls() {
  int auto_exposure = options_.auto_exposure;
  if (options_.exposure_absolute >= 0 && auto_exposure < 0) auto_exposure = 0;  // needs manual
  if (auto_exposure == 1 && options_.exposure_absolute >= 0) {
    Log(LogLevel::kWarn, options_.device + ": exposure_absolute is ignored by most cameras while "
                                           "auto exposure is on");
  }
  if (auto_exposure >= 0) {
    SetControl(V4L2_CID_EXPOSURE_AUTO, "exposure_auto",
               auto_exposure == 1 ? V4L2_EXPOSURE_AUTO : V4L2_EXPOSURE_MANUAL);
  }
  if (options_.exposure_absolute >= 0) {
    SetControl(V4L2_CID_EXPOSURE_ABSOLUTE, "exposure_absolute", options_.exposure_absolute);
  }
  if (options_.gain >= 0) SetControl(V4L2_CID_GAIN, "gain", options_.gain);
}

void V4l2Camera::ReadBackExposure() {
  negotiated_.exposure_auto = -1;
  negotiated_.exposure_s = 0;
  v4l2_control mode{};
  mode.id = V4L2_CID_EXPOSURE_AUTO;
  if (io_->Ioctl(fd_, VIDIOC_G_CTRL, &mode) < 0) return;
  negotiated_.exposure_auto = mode.value;
  const bool manual_asked = options_.auto_exposure == 0 || (options_.exposure_absolute >= 0 && options_.auto_exposure < 0);
  if (manual_asked && mode.value != V4L2_EXPOSURE_MANUAL) {
    Log(LogLevel::kWarn, options_.device + ": manual exposure was asked for, the driver holds " +
                             DescribeExposure(negotiated_));
  }
  // A fixed exposure time: manual, or shutter priority (the camera varies the aperture).
  if (mode.value != V4L2_EXPOSURE_MANUAL && mode.value != V4L2_EXPOSURE_SHUTTER_PRIORITY) return;
  v4l2_control time{};
  time.id = V4L2_CID_EXPOSURE_ABSOLUTE;
  if (io_->Ioctl(fd_, VIDIOC_G_CTRL, &time) < 0 || time.value <= 0) return;
  negotiated_.exposure_s = time.value * 1e-4;  // V4L2_CID_EXPOSURE_ABSOLUTE counts 100 us
  const double fps = negotiated_.fps > 0 ? negotiated_.fps : options_.fps;
  if (fps > 0 && negotiated_.exposure_s > 1.001 / fps) {
    Log(LogLevel::kWarn, options_.device + ": exposure " + DescribeExposure(negotiated_) +
                             " outlasts a frame period at " + FpsText(fps) + " fps: the camera delivers at most " +
                             FpsText(1.0 / negotiated_.exposure_s) + " fps (the loss timeout waits for " +
                             "5 exposures)");
  }
}

double V4l2Camera::LossTimeout() const {
  return std::max({options_.timeout_s, negotiated_.fps > 0 ? 5.0 / negotiated_.fps : 0.0,
                   5.0 * negotiated_.exposure_s});
}

bool V4l2Camera::SetupBuffers() {
  v4l2_requestbuffers req{};
  req.count = static_cast<uint32_t>(std::max(2, options_.buffers));
  req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  req.memory = V4L2_MEMORY_MMAP;
  if (io_->Ioctl(fd_, VIDIOC_REQBUFS, &req) < 0) {
    const int err = errno;
    return Fail("VIDIOC_REQBUFS (" + std::to_string(options_.buffers) +
                " mmap buffers) failed: " + ErrnoText(err) +
                (err == EBUSY ? "; another program is using the camera" : ""));
  }
  if (req.count < 2) {
    return Fail("the driver granted " + std::to_string(req.count) + " buffers, need at least 2");
  }
  for (uint32_t i = 0; i < req.count; ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (io_->Ioctl(fd_, VIDIOC_QUERYBUF, &buf) < 0) {
      const int err = errno;
      return Fail("VIDIOC_QUERYBUF " + std::to_string(i) + " failed: " + ErrnoText(err));
    }
    void* start = io_->Mmap(buf.length, fd_, static_cast<off_t>(buf.m.offset));
    if (start == MAP_FAILED) {
      const int err = errno;
      return Fail("mmap of buffer " + std::to_string(i) + " failed: " + ErrnoText(err));
    }
    buffers_.push_back(Buffer{start, buf.length});
  }
  for (uint32_t i = 0; i < buffers_.size(); ++i) {
    v4l2_buffer buf{};
    buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buf.memory = V4L2_MEMORY_MMAP;
    buf.index = i;
    if (io_->Ioctl(fd_, VIDIOC_QBUF, &buf) < 0) {
      const int err = errno;
      return Fail("VIDIOC_QBUF " + std::to_string(i) + " failed: " + ErrnoText(err));
    }
  }
  negotiated_.buffers = static_cast<int>(buffers_.size());
  return true;
}

void V4l2Camera::ReleaseDevice() {
  if (fd_ >= 0 && streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    io_->Ioctl(fd_, VIDIOC_STREAMOFF, &type);  // fails harmlessly on an unplugged device
  }
  streaming_ = false;
  for (const Buffer& b : buffers_) io_->Munmap(b.start, b.length);
  if (fd_ >= 0 && !buffers_.empty()) {
    v4l2_requestbuffers req{};  // count 0 frees the driver's buffers
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    io_->Ioctl(fd_, VIDIOC_REQBUFS, &req);
  }
  buffers_.clear();
  if (fd_ >= 0) io_->Close(fd_);
  fd_ = -1;
}

void V4l2Camera::Lost(const std::string& why) {
  ++stats_.losses;
  ReleaseDevice();
  error_ = options_.device + ": " + why;
  state_ = "reconnecting";
  backoff_s_ = options_.backoff_initial_s;
  next_attempt_mono_ns_ = clock_->MonotonicNs() + static_cast<int64_t>(backoff_s_ * 1e9);
  Log(LogLevel::kError, error_ + "; device released, reopening in " + FpsText(backoff_s_) + " s");
}

ReadStatus V4l2Camera::Read(Frame* frame, double max_wait_s) {
  const int64_t max_wait_ns = static_cast<int64_t>(std::max(0.0, max_wait_s) * 1e9);
  if (!streaming()) {
    const int64_t now = clock_->MonotonicNs();
    if (now < next_attempt_mono_ns_) {
      clock_->SleepNs(std::min(next_attempt_mono_ns_ - now, max_wait_ns));
      if (clock_->MonotonicNs() < next_attempt_mono_ns_) return ReadStatus::kNoFrame;
    }
    const bool was_lost = state_ == "reconnecting";
    if (!OpenDevice()) {
      ++stats_.open_failures;
      backoff_s_ = std::min(backoff_s_ * 2.0, options_.backoff_max_s);
      next_attempt_mono_ns_ = clock_->MonotonicNs() + static_cast<int64_t>(backoff_s_ * 1e9);
      if (was_lost) state_ = "reconnecting";
      else state_ = "waiting for device";
      return ReadStatus::kError;
    }
    if (was_lost) {
      ++stats_.reconnects;
      Log(LogLevel::kInfo, options_.device + ": reconnected");
    }
    backoff_s_ = options_.backoff_initial_s;
  }

  const int64_t now = clock_->MonotonicNs();
  // A slow camera (a long exposure at night) must not be mistaken for a dead one.
  const double timeout_s = LossTimeout();
  const int64_t loss_deadline = last_frame_mono_ns_ + static_cast<int64_t>(timeout_s * 1e9);
  const int64_t wait_ns = std::max<int64_t>(0, std::min(max_wait_ns, loss_deadline - now));
  short revents = 0;
  const int r = io_->Poll(fd_, static_cast<int>((wait_ns + 999999) / 1000000), &revents);
  if (r < 0) {
    if (errno == EINTR) return ReadStatus::kNoFrame;
    Lost("poll failed: " + ErrnoText(errno));
    return ReadStatus::kError;
  }
  if (r == 0) {
    if (clock_->MonotonicNs() >= loss_deadline) {
      ++stats_.timeouts;
      Lost(NoGoodFrameText(timeout_s));
      return ReadStatus::kError;
    }
    return ReadStatus::kNoFrame;
  }
  if ((revents & (POLLERR | POLLHUP | POLLNVAL)) && !(revents & POLLIN)) {
    Lost("poll reports an error on the device (unplugged?)");
    return ReadStatus::kError;
  }

  v4l2_buffer buf{};
  buf.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  buf.memory = V4L2_MEMORY_MMAP;
  if (io_->Ioctl(fd_, VIDIOC_DQBUF, &buf) < 0) {
    const int err = errno;
    if (err == EAGAIN) return ReadStatus::kNoFrame;
    Lost("VIDIOC_DQBUF failed: " + ErrnoText(err));
    return ReadStatus::kError;
  }
  if (buf.index >= buffers_.size()) {
    Lost("VIDIOC_DQBUF returned buffer index " + std::to_string(buf.index) + " of " +
         std::to_string(buffers_.size()));
    return ReadStatus::kError;
  }

  // Sequence gaps are frames the driver had to drop (no free buffer, USB bandwidth, ...).
  // Unsigned arithmetic handles the 32-bit wrap; a backwards jump (driver restart) is not a drop.
  if (have_sequence_) {
    const uint32_t step = buf.sequence - last_sequence_;
    if (step >= 1 && step < 0x80000000u) stats_.drops += step - 1;
  }
  have_sequence_ = true;
  last_sequence_ = buf.sequence;

  ReadStatus status = ReadStatus::kFrame;
  if (buf.flags & V4L2_BUF_FLAG_ERROR) {
    ++stats_.corrupt;
    error_ = options_.device + ": driver flagged frame " + std::to_string(buf.sequence) +
             " as corrupt";
    status = ReadStatus::kBadFrame;
  } else {
    const Buffer& b = buffers_[buf.index];
    // bytesused 0 on a compressed format is an empty frame (the buffer still holds an older
    // JPEG, which would be published as new); raw formats fill the buffer by definition.
    const size_t used = buf.bytesused > 0                        ? std::min<size_t>(buf.bytesused, b.length)
                        : negotiated_.format == PixelFormat::kMjpeg ? 0
                                                                    : b.length;
    std::string why;
    if (!ConvertToImage(negotiated_.format, static_cast<const uint8_t*>(b.start), used,
                        negotiated_.width, negotiated_.height, negotiated_.bytes_per_line,
                        &frame->image, &why)) {
      ++stats_.corrupt;
      error_ = options_.device + ": frame " + std::to_string(buf.sequence) + ": " + why;
      status = ReadStatus::kBadFrame;
    } else {
      const int64_t driver_ns = static_cast<int64_t>(buf.timestamp.tv_sec) * 1000000000LL +
                                static_cast<int64_t>(buf.timestamp.tv_usec) * 1000LL;
      const DriverClock kind =
          (buf.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC
              ? DriverClock::kMonotonic
              : DriverClock::kUnknown;
      frame->stamp_ns = stamper_.Map(driver_ns, kind);
      frame->encoding = RosEncodingFor(negotiated_.format);
      frame->sequence = buf.sequence;
      ++stats_.frames;
      // Only a good frame holds the loss deadline off: a camera that sends nothing but frames the
      // driver flags or that do not convert (wedged, a wrong-size MJPEG) was never reopened.
      last_frame_mono_ns_ = clock_->MonotonicNs();
      corrupt_at_last_good_ = stats_.corrupt;
    }
  }
  // Hand the buffer back to the driver (the frame owns a copy of the pixels).
  if (io_->Ioctl(fd_, VIDIOC_QBUF, &buf) < 0) {
    const int err = errno;
    Lost("VIDIOC_QBUF failed: " + ErrnoText(err));
    // The loss is the news, even after a good frame (which is dropped): returned as kFrame, the
    // loss went uncounted by the node and its diagnostics named an older error.
    status = ReadStatus::kError;
  } else if (status == ReadStatus::kBadFrame && clock_->MonotonicNs() >= loss_deadline) {
    ++stats_.timeouts;
    Lost(NoGoodFrameText(timeout_s));
    status = ReadStatus::kError;
  }
  return status;
}

std::string V4l2Camera::NoGoodFrameText(double timeout_s) const {
  if (stats_.corrupt == corrupt_at_last_good_) return "no frame for " + FpsText(timeout_s) + " s";
  return "no good frame for " + FpsText(timeout_s) + " s, " + std::to_string(stats_.corrupt - corrupt_at_last_good_) +
         " unreadable (the last: " + error_ + ")";
}

std::string V4l2Camera::Describe() const {
  std::ostringstream s;
  s << options_.device;
  if (negotiated_.width > 0) s << " " << DescribeNegotiated(negotiated_);
  return s.str();
}

std::map<std::string, std::string> V4l2Camera::Status() const {
  std::map<std::string, std::string> m{
      {"source", "v4l2"},
      {"device", options_.device},
      {"state", state_},
      {"requested format",
       std::to_string(options_.width) + "x" + std::to_string(options_.height) + " " +
           PixelFormatName(options_.format) + " @" + FpsText(options_.fps) + " fps"},
      {"frames", std::to_string(stats_.frames)},
      {"dropped frames", std::to_string(stats_.drops)},
      {"corrupt frames", std::to_string(stats_.corrupt)},
      {"device losses", std::to_string(stats_.losses)},
      {"timeouts", std::to_string(stats_.timeouts)},
      {"reconnects", std::to_string(stats_.reconnects)},
      {"open failures", std::to_string(stats_.open_failures)},
      {"clock offset ros-driver [s]", std::to_string(stamper_.OffsetNs() * 1e-9)},
      {"last error", error_}};
  if (ever_opened_) {
    m["negotiated format"] = DescribeNegotiated(negotiated_);
    m["exposure"] = DescribeExposure(negotiated_);
    m["loss timeout [s]"] = std::to_string(LossTimeout());
    m["card"] = negotiated_.card + " (" + negotiated_.driver + ", " + negotiated_.bus + ")";
  }
  return m;
}

}  // namespace sensors
}  // namespace clothwind
