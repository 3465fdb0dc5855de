#include "sensors/frame_source.h"

#include <algorithm>
#include <cmath>

namespace clothwind {
namespace sensors {
namespace {

// A recording that fell this far behind its schedule (node stalled, debugger) restarts the
// schedule instead of bursting frames out to catch up.
constexpr int64_t kMaxLagNs = 500000000LL;

}  // namespace

FramePacer::FramePacer(Clock* clock, double rate_hz) : clock_(clock), rate_hz_(rate_hz) {}

void FramePacer::Restart() { started_ = false; }

bool FramePacer::WaitNext(double max_wait_s, int64_t* stamp_ns) {
  if (!started_) {
    start_mono_ns_ = clock_->MonotonicNs();
    start_ros_ns_ = clock_->RosNs();
    index_ = 0;
    started_ = true;
  }
  const auto due_after_start = [this](int64_t k) {
    return static_cast<int64_t>(std::llround(static_cast<double>(k) * 1e9 / rate_hz_));
  };
  int64_t due = start_mono_ns_ + due_after_start(index_);
  int64_t now = clock_->MonotonicNs();
  if (now - due > kMaxLagNs) {
    start_ros_ns_ += now - start_mono_ns_;
    start_mono_ns_ = now;
    index_ = 0;
    due = now;
  }
  if (due > now) {
    const int64_t max_wait_ns = static_cast<int64_t>(std::max(0.0, max_wait_s) * 1e9);
    clock_->SleepNs(std::min(due - now, max_wait_ns));
    now = clock_->MonotonicNs();
    if (now < due) return false;
  }
  *stamp_ns = start_ros_ns_ + (due - start_mono_ns_);
  ++index_;
  return true;
}

}  // namespace sensors
}  // namespace clothwind
