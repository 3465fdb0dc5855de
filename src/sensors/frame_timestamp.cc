#include "sensors/frame_timestamp.h"

#include <time.h>

#include <cerrno>

namespace clothwind {
namespace sensors {
namespace {

int64_t ReadClockNs(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

}  // namespace

int64_t SystemClock::MonotonicNs() { return ReadClockNs(CLOCK_MONOTONIC); }

int64_t SystemClock::RosNs() { return ReadClockNs(CLOCK_REALTIME); }

void SystemClock::SleepNs(int64_t duration_ns) {
  if (duration_ns <= 0) return;
  timespec req{static_cast<time_t>(duration_ns / 1000000000LL),
               static_cast<long>(duration_ns % 1000000000LL)};
  timespec rem{};
  while (nanosleep(&req, &rem) != 0 && errno == EINTR) req = rem;
}

ClockOffsetEstimator::ClockOffsetEstimator(int window) : window_(window < 1 ? 1 : window) {}

void ClockOffsetEstimator::AddSample(int64_t source_ns, int64_t ros_ns) {
  const int64_t offset = ros_ns - source_ns;
  const int64_t index = count_++;
  // Samples that are larger than the new one can never be the minimum again.
  while (!window_min_.empty() && window_min_.back().second >= offset) window_min_.pop_back();
  window_min_.emplace_back(index, offset);
  while (window_min_.front().first <= index - window_) window_min_.pop_front();
}

void ClockOffsetEstimator::Reset() {
  window_min_.clear();
  count_ = 0;
}

FrameTimestamper::FrameTimestamper(Clock* clock, int window) : clock_(clock), estimator_(window) {}

int64_t FrameTimestamper::Map(int64_t driver_ns, DriverClock kind) {
  if (driver_ns <= 0) return clock_->RosNs();
  if (!have_kind_ || kind != kind_) {
    estimator_.Reset();  // offsets of different clocks must not mix
    kind_ = kind;
    have_kind_ = true;
  }
  if (kind == DriverClock::kMonotonic) {
    // Monotonic first, ROS second: any delay between the reads only enlarges the offset.
    const int64_t mono = clock_->MonotonicNs();
    const int64_t ros = clock_->RosNs();
    estimator_.AddSample(mono, ros);
  } else {
    estimator_.AddSample(driver_ns, clock_->RosNs());
  }
  return driver_ns + estimator_.OffsetNs();
}

void FrameTimestamper::Reset() {
  estimator_.Reset();
  have_kind_ = false;
}

}  // namespace sensors
}  // namespace clothwind
