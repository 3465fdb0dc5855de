#ifndef CLOTHWIND_SENSORS_V4L2_FAKE_DEVICE_H_
#define CLOTHWIND_SENSORS_V4L2_FAKE_DEVICE_H_

// An emulated V4L2 capture driver behind the V4l2Io seam, for tests and benches. It behaves
// like a UVC webcam where it matters to the capture code: it forces its own image size and frame
// rate whatever is asked, grants fewer buffers than requested, fills buffers at a fixed period in
// fake time with CLOCK_MONOTONIC capture stamps and a dequeue latency, skips sequence numbers to
// simulate dropped frames, and can be unplugged (ENODEV on every call, like uvcvideo) and
// replugged, or stalled (no frames, poll times out).

#include <linux/videodev2.h>
#include <poll.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "sensors/frame_timestamp_fake_clock.h"
#include "sensors/v4l2_io.h"

namespace clothwind {
namespace sensors {

struct FakeV4l2Control {
  int32_t minimum = 0, maximum = 255, value = 0;
  uint32_t type = V4L2_CTRL_TYPE_INTEGER;
};

struct FakeV4l2Config {
  std::vector<uint32_t> formats{V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_GREY};
  int width = 320, height = 240;  // the only size this "sensor" has [px]
  int row_padding = 16;           // bytesperline = width * bytes per pixel + this
  uint32_t fps = 15;              // the only frame rate [Hz]
  bool timeperframe = true;       // driver lets the rate be "set" (V4L2_CAP_TIMEPERFRAME)
  uint32_t max_buffers = 3;       // grants min(asked, this)
  int64_t latency_ns = 12000000;  // capture instant -> buffer dequeueable, plus jitter below
  int64_t jitter_ns = 4000000;    // latency varies by 0..4 steps of this, deterministically
  bool monotonic = true;          // V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC (else _UNKNOWN)
  std::map<uint64_t, uint32_t> skip_before;  // before capture k, the driver loses n frames
  uint32_t first_sequence = 0;                // the driver's frame counter at the first capture
  // GREY frames vary by row and column (value + r + 2 c, mod 256) instead of being uniform, so a
  // reader that takes the row padding for image shows.
  bool gradient = false;
  std::set<uint64_t> sequence_restart_before;  // before capture k the counter restarts at 0 (one open)
  // Capture k reports bytesused n instead of the frame's size (0: an empty frame; fewer: a frame
  // cut short), its buffer filled as usual.
  std::map<uint64_t, uint32_t> bytesused_of;
  // Captures from this one on are flagged V4L2_BUF_FLAG_ERROR (a wedged camera); none by default.
  uint64_t error_from = UINT64_MAX;
  // Unplugged right after capture k is dequeued (before the reader hands its buffer back).
  uint64_t unplug_after = UINT64_MAX;
  std::map<uint32_t, FakeV4l2Control> controls{
      {V4L2_CID_EXPOSURE_AUTO, {0, 3, 3, V4L2_CTRL_TYPE_MENU}},
      {V4L2_CID_GAIN, {0, 100, 10, V4L2_CTRL_TYPE_INTEGER}}};
};

class FakeV4l2Device : public V4l2Io {
 public:
  FakeV4l2Device(FakeClock* clock, FakeV4l2Config config)
      : clock_(clock), config_(config), sequence_(config.first_sequence) {}

  // --- test controls ---
  void Unplug() { present_ = false; }
  // A new device instance counts from zero; first_sequence: one that counts on from elsewhere.
  void Replug(uint32_t first_sequence = 0) {
    present_ = true;
    sequence_ = first_sequence;
  }
  void Stall(bool stalled) { stalled_ = stalled; }

  // --- observations ---
  int open_fds() const { return static_cast<int>(fds_.size()); }
  int mapped_buffers() const {
    int n = 0;
    for (const auto& b : buffers_) n += b.mapped ? 1 : 0;
    return n;
  }
  bool streaming() const { return streaming_; }
  // STREAMOFF attempts (also those that failed on an unplugged device).
  int streamoff_calls() const { return streamoff_calls_; }
  const std::vector<int64_t>& open_attempts_ns() const { return open_attempts_ns_; }
  const std::map<uint32_t, FakeV4l2Control>& controls() const { return config_.controls; }
  // Capture instants (CLOCK_MONOTONIC [ns]) of the frames handed out, in order.
  const std::vector<int64_t>& delivered_capture_ns() const { return delivered_capture_ns_; }
  // Pixel value frame k carries (GREY: every pixel; YUYV: every Y; MJPEG: blue channel).
  static uint8_t FrameValue(uint64_t k) { return static_cast<uint8_t>(40 + (k * 13) % 180); }

  // --- V4l2Io ---
  int Open(const std::string& path) override {
    open_attempts_ns_.push_back(clock_->MonotonicNs());
    if (!present_) return SetErrno(ENOENT);
    const int fd = next_fd_++;
    fds_.insert(fd);
    return fd;
  }

  int Close(int fd) override {
    if (!fds_.erase(fd)) return SetErrno(EBADF);
    if (fd == stream_fd_) {  // the driver releases a closing owner's queue
      streaming_ = false;
      stream_fd_ = -1;
      queue_.clear();
      bool any_mapped = false;
      for (const auto& b : buffers_) any_mapped |= b.mapped;
      if (!any_mapped) buffers_.clear();
    }
    return 0;
  }

  int Ioctl(int fd, unsigned long request, void* arg) override {
    if (!fds_.count(fd)) return SetErrno(EBADF);
    if (request == VIDIOC_STREAMOFF) ++streamoff_calls_;  // attempts count, even when unplugged
    if (!present_) return SetErrno(ENODEV);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        std::memset(cap, 0, sizeof(*cap));
        std::strncpy(reinterpret_cast<char*>(cap->driver), "fakecam", sizeof(cap->driver));
        std::strncpy(reinterpret_cast<char*>(cap->card), "Fake Camera", sizeof(cap->card));
        std::strncpy(reinterpret_cast<char*>(cap->bus_info), "usb-fake-1", sizeof(cap->bus_info));
        cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
        cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        if (d->index >= config_.formats.size()) return SetErrno(EINVAL);
        d->pixelformat = config_.formats[d->index];
        return 0;
      }
      case VIDIOC_S_FMT: {
        if (streaming_) return SetErrno(EBUSY);
        auto* f = static_cast<v4l2_format*>(arg);
        bool offered = false;
        for (uint32_t p : config_.formats) offered |= p == f->fmt.pix.pixelformat;
        if (!offered) f->fmt.pix.pixelformat = config_.formats.front();
        f->fmt.pix.width = config_.width;
        f->fmt.pix.height = config_.height;
        f->fmt.pix.field = V4L2_FIELD_NONE;
        const uint32_t pf = f->fmt.pix.pixelformat;
        const int bpp = pf == V4L2_PIX_FMT_GREY ? 1 : 2;
        f->fmt.pix.bytesperline = pf == V4L2_PIX_FMT_MJPEG ? 0 : config_.width * bpp + config_.row_padding;
        f->fmt.pix.sizeimage = pf == V4L2_PIX_FMT_MJPEG ? config_.width * config_.height * 2
                                                        : f->fmt.pix.bytesperline * config_.height;
        format_ = *f;
        return 0;
      }
      case VIDIOC_G_FMT:
        *static_cast<v4l2_format*>(arg) = format_;
        return 0;
      case VIDIOC_G_PARM:
      case VIDIOC_S_PARM: {  // S_PARM: whatever is asked, the sensor runs at its one rate
        auto* p = static_cast<v4l2_streamparm*>(arg);
        std::memset(&p->parm, 0, sizeof(p->parm));
        p->parm.capture.capability = config_.timeperframe ? V4L2_CAP_TIMEPERFRAME : 0;
        p->parm.capture.timeperframe = {1, config_.fps};
        return 0;
      }
      case VIDIOC_QUERYCTRL: {
        auto* q = static_cast<v4l2_queryctrl*>(arg);
        auto it = config_.controls.find(q->id);
        if (it == config_.controls.end()) return SetErrno(EINVAL);
        q->type = it->second.type;
        q->minimum = it->second.minimum;
        q->maximum = it->second.maximum;
        q->step = 1;
        q->flags = 0;
        return 0;
      }
      case VIDIOC_G_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        auto it = config_.controls.find(c->id);
        if (it == config_.controls.end()) return SetErrno(EINVAL);
        c->value = it->second.value;
        return 0;
      }
      case VIDIOC_S_CTRL: {
        auto* c = static_cast<v4l2_control*>(arg);
        auto it = config_.controls.find(c->id);
        if (it == config_.controls.end()) return SetErrno(EINVAL);
        if (c->value < it->second.minimum || c->value > it->second.maximum) return SetErrno(ERANGE);
        // Like UVC cameras: no full-auto exposure mode, only manual (1) and aperture priority (3).
        if (c->id == V4L2_CID_EXPOSURE_AUTO && c->value != V4L2_EXPOSURE_MANUAL &&
            c->value != V4L2_EXPOSURE_APERTURE_PRIORITY) {
          return SetErrno(EINVAL);
        }
        it->second.value = c->value;
        return 0;
      }
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (r->memory != V4L2_MEMORY_MMAP) return SetErrno(EINVAL);
        if (streaming_) return SetErrno(EBUSY);
        for (const auto& b : buffers_) if (b.mapped) return SetErrno(EBUSY);
        buffers_.clear();
        queue_.clear();
        r->count = std::min(r->count, config_.max_buffers);
        for (uint32_t i = 0; i < r->count; ++i) {
          buffers_.push_back(FakeBuffer{std::vector<uint8_t>(format_.fmt.pix.sizeimage), false, false});
        }
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return SetErrno(EINVAL);
        b->length = static_cast<uint32_t>(buffers_[b->index].mem.size());
        b->m.offset = OffsetOf(b->index);
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size() || buffers_[b->index].queued) return SetErrno(EINVAL);
        buffers_[b->index].queued = true;
        queue_.push_back(b->index);
        return 0;
      }
      case VIDIOC_DQBUF:
        return Dequeue(static_cast<v4l2_buffer*>(arg));
      case VIDIOC_STREAMON:
        if (buffers_.empty()) return SetErrno(EINVAL);
        streaming_ = true;
        stream_fd_ = fd;
        next_capture_ns_ = clock_->MonotonicNs() + Period();
        return 0;
      case VIDIOC_STREAMOFF:
        streaming_ = false;
        queue_.clear();
        for (auto& b : buffers_) b.queued = false;
        return 0;
      default:
        return SetErrno(ENOTTY);
    }
  }

  void* Mmap(size_t length, int fd, off_t offset) override {
    if (!present_) {
      errno = ENODEV;
      return MAP_FAILED;
    }
    for (uint32_t i = 0; i < buffers_.size(); ++i) {
      if (OffsetOf(i) == static_cast<uint32_t>(offset) && length <= buffers_[i].mem.size()) {
        buffers_[i].mapped = true;
        return buffers_[i].mem.data();
      }
    }
    errno = EINVAL;
    return MAP_FAILED;
  }

  int Munmap(void* address, size_t length) override {
    for (auto& b : buffers_) {
      if (b.mem.data() == address) {
        b.mapped = false;
        return 0;
      }
    }
    return SetErrno(EINVAL);
  }

  int Poll(int fd, int timeout_ms, short* revents) override {
    const int64_t timeout_ns = static_cast<int64_t>(timeout_ms) * 1000000;
    if (!present_) {
      *revents = POLLERR | POLLHUP;
      return 1;
    }
    if (!streaming_ || queue_.empty()) {
      *revents = POLLERR;  // V4L2: nothing can ever be dequeued
      return 1;
    }
    const int64_t ready = NextReadyNs();
    const int64_t now = clock_->MonotonicNs();
    if (!stalled_ && ready <= now + timeout_ns) {
      if (ready > now) clock_->Advance(ready - now);
      *revents = POLLIN;
      return 1;
    }
    clock_->SleepNs(timeout_ns);
    *revents = 0;
    return 0;
  }

 private:
  struct FakeBuffer {
    std::vector<uint8_t> mem;
    bool queued = false;
    bool mapped = false;
  };

  static int SetErrno(int e) {
    errno = e;
    return -1;
  }
  static uint32_t OffsetOf(uint32_t index) { return index * 0x100000u; }
  // The frame period: the sensor's rate, or longer when a manual exposure outlasts it (UVC
  // cameras' exposure_auto_priority).
  int64_t Period() const {
    int64_t period = 1000000000LL / config_.fps;
    const auto mode = config_.controls.find(V4L2_CID_EXPOSURE_AUTO);
    const auto time = config_.controls.find(V4L2_CID_EXPOSURE_ABSOLUTE);
    if (mode != config_.controls.end() && mode->second.value == V4L2_EXPOSURE_MANUAL &&
        time != config_.controls.end())
      period = std::max<int64_t>(period, static_cast<int64_t>(time->second.value) * 100000);
    return period;
  }
  int64_t LatencyOf(uint64_t k) const {
    return config_.latency_ns + static_cast<int64_t>((k * 7919) % 5) * config_.jitter_ns;
  }
  int64_t NextReadyNs() {
    // Frames lost before capture k take their time slots too.
    auto it = config_.skip_before.find(captures_);
    if (it != config_.skip_before.end() && !skip_applied_) {
      sequence_ += it->second;
      next_capture_ns_ += it->second * Period();
      skip_applied_ = true;
    }
    return next_capture_ns_ + LatencyOf(captures_);
  }

  int Dequeue(v4l2_buffer* b) {
    if (!streaming_) return SetErrno(EINVAL);
    if (queue_.empty() || stalled_ || NextReadyNs() > clock_->MonotonicNs()) return SetErrno(EAGAIN);
    const uint32_t index = queue_.front();
    queue_.pop_front();
    FakeBuffer& buf = buffers_[index];
    buf.queued = false;
    if (config_.sequence_restart_before.count(captures_)) sequence_ = 0;
    const uint8_t value = FrameValue(captures_);
    uint32_t bytes = Fill(&buf.mem, value);
    if (auto it = config_.bytesused_of.find(captures_); it != config_.bytesused_of.end()) bytes = it->second;
    std::memset(b, 0, sizeof(*b));
    b->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b->memory = V4L2_MEMORY_MMAP;
    b->index = index;
    b->bytesused = bytes;
    b->length = static_cast<uint32_t>(buf.mem.size());
    b->sequence = sequence_;
    b->flags = config_.monotonic ? V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC : V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
    if (captures_ >= config_.error_from) b->flags |= V4L2_BUF_FLAG_ERROR;
    b->timestamp.tv_sec = next_capture_ns_ / 1000000000LL;
    b->timestamp.tv_usec = (next_capture_ns_ % 1000000000LL) / 1000;
    delivered_capture_ns_.push_back(b->timestamp.tv_sec * 1000000000LL + b->timestamp.tv_usec * 1000LL);
    if (captures_ == config_.unplug_after) present_ = false;
    ++sequence_;
    ++captures_;
    skip_applied_ = false;
    next_capture_ns_ += Period();
    return 0;
  }

  uint32_t Fill(std::vector<uint8_t>* mem, uint8_t value) {
    const uint32_t pf = format_.fmt.pix.pixelformat;
    const int w = config_.width, h = config_.height;
    const int stride = static_cast<int>(format_.fmt.pix.bytesperline);
    if (pf == V4L2_PIX_FMT_MJPEG) {
      cv::Mat bgr(h, w, CV_8UC3, cv::Scalar(value, 128, 128));
      std::vector<uint8_t> jpeg;
      cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
      std::fill(mem->begin(), mem->end(), 0);
      std::copy(jpeg.begin(), jpeg.end(), mem->begin());
      return static_cast<uint32_t>(jpeg.size());
    }
    std::fill(mem->begin(), mem->end(), 0xEE);  // row padding stays visible garbage
    for (int r = 0; r < h; ++r) {
      uint8_t* row = mem->data() + r * stride;
      if (pf == V4L2_PIX_FMT_GREY && config_.gradient) {
        for (int c = 0; c < w; ++c) row[c] = static_cast<uint8_t>(value + r + 2 * c);
      } else if (pf == V4L2_PIX_FMT_GREY) {
        std::memset(row, value, w);
      } else {  // YUYV, neutral chroma
        for (int c = 0; c < w; ++c) {
          row[2 * c] = value;
          row[2 * c + 1] = 128;
        }
      }
    }
    return static_cast<uint32_t>(stride * h);
  }

  FakeClock* clock_;
  FakeV4l2Config config_;
  bool present_ = true;
  bool stalled_ = false;
  bool streaming_ = false;
  int stream_fd_ = -1;
  int next_fd_ = 3;
  std::set<int> fds_;
  v4l2_format format_{};
  std::vector<FakeBuffer> buffers_;
  std::deque<uint32_t> queue_;
  int64_t next_capture_ns_ = 0;
  uint32_t sequence_ = 0;
  uint64_t captures_ = 0;
  bool skip_applied_ = false;
  int streamoff_calls_ = 0;
  std::vector<int64_t> open_attempts_ns_;
  std::vector<int64_t> delivered_capture_ns_;
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_V4L2_FAKE_DEVICE_H_
