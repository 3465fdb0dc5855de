#include "ros_bridge/sdn_conversions.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <boost/make_shared.hpp>

namespace clothwind::ros_bridge {

std::vector<cv::Mat> ClipFrames(const clothwind::Clip& msg) {
  if (msg.encoding != "mono8" && msg.encoding != "bgr8") {
    throw std::invalid_argument("Clip.encoding must be \"mono8\" or \"bgr8\", got \"" + msg.encoding + "\"");
  }
  const int channels = msg.encoding == "bgr8" ? 3 : 1;
  if (msg.num_frames == 0 || msg.width == 0 || msg.height == 0) {
    throw std::invalid_argument("Clip.num_frames, width and height must be positive (got " +
                                std::to_string(msg.num_frames) + ", " + std::to_string(msg.width) + ", " +
                                std::to_string(msg.height) + ")");
  }
  // Bounded before they are multiplied: sizes whose product wraps round 2^64 once passed the
  // data size check with a few bytes, and the frames then read far outside them (a crash).
  if (msg.width > kMaxClipSide || msg.height > kMaxClipSide || msg.num_frames > kMaxClipFrames) {
    throw std::invalid_argument("Clip width and height must be at most " + std::to_string(kMaxClipSide) +
                                " px and num_frames at most " + std::to_string(kMaxClipFrames) + " (got " +
                                std::to_string(msg.width) + " x " + std::to_string(msg.height) + ", " +
                                std::to_string(msg.num_frames) + " frames)");
  }
  // Square, as the clip buffer crops it (msg/Clip.msg): the network resizes a clip to its square
  // input, and a 2000 x 2 strip was stretched into one and estimated, diagnostics OK.
  if (msg.width != msg.height || msg.width < kMinClipSide) {
    throw std::invalid_argument("Clip width and height must be equal (a square crop) and at least " +
                                std::to_string(kMinClipSide) + " px (got " + std::to_string(msg.width) + " x " +
                                std::to_string(msg.height) + ")");
  }
  const size_t frame = static_cast<size_t>(msg.width) * msg.height * channels;
  const size_t expected = frame * msg.num_frames;
  if (msg.data.size() != expected) {
    throw std::invalid_argument("Clip.data has " + std::to_string(msg.data.size()) +
                                " bytes, num_frames x height x width x channels = " + std::to_string(msg.num_frames) +
                                " x " + std::to_string(msg.height) + " x " + std::to_string(msg.width) + " x " +
                                std::to_string(channels) + " = " + std::to_string(expected));
  }
  if (!msg.frame_stamps.empty() && msg.frame_stamps.size() != msg.num_frames) {
    throw std::invalid_argument("Clip.frame_stamps has " + std::to_string(msg.frame_stamps.size()) +
                                " stamps for num_frames = " + std::to_string(msg.num_frames));
  }
  // A clip stamped 0 (a publisher that never set the stamp) would be estimated at the epoch, and
  // every such estimate at the same time: the trailing mean would never let one go.
  if (msg.frame_stamps.empty() ? msg.header.stamp.isZero() : msg.frame_stamps.front().isZero()) {
    throw std::invalid_argument(std::string(msg.frame_stamps.empty() ? "Clip.header.stamp" : "Clip.frame_stamps[0]") +
                                " is 0 (unset); a clip is stamped with its first frame's capture time");
  }
  for (size_t i = 1; i < msg.frame_stamps.size(); ++i) {
    if (!(msg.frame_stamps[i] > msg.frame_stamps[i - 1])) {
      throw std::invalid_argument("Clip.frame_stamps must be strictly increasing; stamp " + std::to_string(i) +
                                  " (" + std::to_string(msg.frame_stamps[i].toSec()) + " s) follows " +
                                  std::to_string(msg.frame_stamps[i - 1].toSec()) + " s");
    }
  }
  std::vector<cv::Mat> frames;
  frames.reserve(msg.num_frames);
  for (uint32_t i = 0; i < msg.num_frames; ++i) {
    frames.emplace_back(static_cast<int>(msg.height), static_cast<int>(msg.width), CV_8UC(channels),
                        const_cast<uint8_t*>(msg.data.data() + i * frame));
  }
  return frames;
}

void CheckClipFrameRate(const clothwind::Clip& msg, double model_rate) {
  // Frequencies are read in Hz at the model's rate: a clip resampled at another rate would shift
  // every spectral peak and the speed with it, silently.
  if (!std::isfinite(msg.frame_rate) || !(msg.frame_rate > 0) ||
      std::abs(msg.frame_rate - model_rate) > 0.01 * model_rate) {
    throw std::invalid_argument("Clip.frame_rate is " + std::to_string(msg.frame_rate) + " Hz, the model reads " +
                                std::to_string(model_rate) + " Hz clips (clip_buffer ~frame_rate)");
  }
  // The spectra assume the frames are 1 / frame_rate apart: a clip whose own stamps say otherwise
  // (a hand-made or edited clip; clip_buffer resamples to exact stamps) would be read at the wrong
  // frequencies. Allowed: 10 % per gap (nanosecond rounding and a camera's jitter are far below).
  const double period = 1.0 / msg.frame_rate;
  for (size_t i = 1; i < msg.frame_stamps.size(); ++i) {
    // As doubles: ros::Time - ros::Time throws std::runtime_error past 2^31 s ([1 s, 3e9 s]
    // passes the increasing-stamps check), reported as the model failing, not a malformed clip.
    const double gap = msg.frame_stamps[i].toSec() - msg.frame_stamps[i - 1].toSec();
    if (std::abs(gap - period) > 0.1 * period) {
      throw std::invalid_argument("Clip.frame_stamps[" + std::to_string(i) + "] is " + std::to_string(gap) +
                                  " s after frame " + std::to_string(i - 1) + ", Clip.frame_rate " +
                                  std::to_string(msg.frame_rate) + " Hz says " + std::to_string(period) +
                                  " s (within 10 %)");
    }
  }
  // And over the whole clip within 1 %, as frame_rate is held: stamps 1/27 s apart passed every
  // gap's 10 % under a 25 Hz rate, and every frequency would read 7 % low.
  if (msg.frame_stamps.size() > 1) {
    const size_t n = msg.frame_stamps.size() - 1;
    const double span = msg.frame_stamps.back().toSec() - msg.frame_stamps.front().toSec();
    if (std::abs(span - n * period) > 0.01 * n * period) {
      throw std::invalid_argument("Clip.frame_stamps span " + std::to_string(span) + " s over " + std::to_string(n) +
                                  " intervals, Clip.frame_rate " + std::to_string(msg.frame_rate) + " Hz says " +
                                  std::to_string(n * period) + " s (within 1 %)");
    }
  }
}

namespace {

// header.stamp + offset [s], refused as a malformed clip (std::invalid_argument) when the sum is
// outside ROS time's 32-bit seconds: ros::Time's own operator threw a runtime_error, which the
// node counted as the model's failure.
ros::Time StampAfter(const clothwind::Clip& clip, double offset) {
  const double t = clip.header.stamp.toSec() + offset;
  if (!(t >= 0 && t < 4294967295.0))
    throw std::invalid_argument("Clip.header.stamp " + std::to_string(clip.header.stamp.toSec()) + " + " +
                                std::to_string(offset) + " s is outside ROS time");
  return ros::Time(t);
}

}  // namespace

ros::Time ClipFrameStamp(const clothwind::Clip& clip, uint32_t i) {
  if (i < clip.frame_stamps.size()) return clip.frame_stamps[i];
  return StampAfter(clip, clip.frame_rate > 0 ? i / clip.frame_rate : 0.0);
}

ros::Time ClipEnd(const clothwind::Clip& clip) {
  if (!clip.frame_stamps.empty()) return clip.frame_stamps.back();
  // header.stamp is the first frame's: the last one is num_frames - 1 periods later.
  const double span = clip.num_frames > 1 && clip.frame_rate > 0 ? (clip.num_frames - 1) / clip.frame_rate : 0.0;
  return StampAfter(clip, span);
}

clothwind::WindEstimate ToWindEstimate(const clothwind::Clip& clip, const learn::Prediction& prediction,
                                       double latency, const std::string& model, uint32_t frames_read) {
  clothwind::WindEstimate e;
  e.header.frame_id = clip.header.frame_id;
  e.header.stamp = ClipEnd(clip);
  e.clip_sequence = clip.sequence;
  // The model reads the clip's last frames_read frames: the estimate is of those.
  const uint32_t first = frames_read > 0 && frames_read < clip.num_frames ? clip.num_frames - frames_read : 0;
  e.clip_start = ClipFrameStamp(clip, first);
  e.clip_end = e.header.stamp;
  e.speed = prediction.speed;
  e.speed_std = prediction.speed_std;
  e.reference_speed = clip.wind_count > 0 ? clip.wind_mean : std::numeric_limits<double>::quiet_NaN();
  e.latency = latency;
  e.model = model;
  return e;
}

sensor_msgs::ImagePtr BgrImageMsg(const cv::Mat& bgr, const std_msgs::Header& header) {
  if (bgr.type() != CV_8UC3) throw std::invalid_argument("BgrImageMsg: expected a CV_8UC3 image");
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header = header;
  msg->height = bgr.rows;
  msg->width = bgr.cols;
  msg->encoding = "bgr8";
  msg->is_bigendian = 0;
  msg->step = bgr.cols * 3;
  msg->data.resize(static_cast<size_t>(msg->step) * bgr.rows);
  for (int r = 0; r < bgr.rows; ++r) std::memcpy(&msg->data[r * msg->step], bgr.ptr(r), msg->step);
  return msg;
}

}  // namespace clothwind::ros_bridge
