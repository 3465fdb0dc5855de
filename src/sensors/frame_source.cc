#include "sensors/frame_source.h"

#include <algorithm>
#include <cmath>

namespace clothwind {
namespace sensors {
namespace {

// A recording that fell this far behind its schedule (node stalled, debugger) restarts the
// schedule instead of bursting frames out to catch up.
constexpr int64_t kMaxLagNs = 500000000LL;
constexpr int64_t kNoClockPollNs = 10000000LL;  // how often to look for /clock [ns]
// Wall time stepped this far from the schedule (NTP's first sync on a field computer, a clock set
// by hand) moves the stamps with it.
constexpr int64_t kMaxClockStepNs = 500000000LL;

}  // namespace

FramePacer::FramePacer(Clock* clock, double rate_hz) : clock_(clock), rate_hz_(rate_hz) {}

void FramePacer::Restart() { started_ = false; }

bool FramePacer::WaitNext(double max_wait_s, int64_t* stamp_ns) {
  const bool simulated = clock_->RosTimeIsSimulated();
  const int64_t max_wait_ns = static_cast<int64_t>(std::max(0.0, max_wait_s) * 1e9);
  const auto pace_now = [&] { return simulated ? clock_->RosNs() : clock_->MonotonicNs(); };
  if (simulated && clock_->RosNs() <= 0) {  // no /clock yet: wait for it rather than stamp 1970
    clock_->SleepNs(std::min(max_wait_ns, kNoClockPollNs));
    return false;
  }
  if (!started_) {
    start_pace_ns_ = pace_now();
    start_ros_ns_ = simulated ? start_pace_ns_ : clock_->RosNs();
    index_ = 0;
    started_ = true;
  }
  const auto due_after_start = [this](int64_t k) {
    return static_cast<int64_t>(std::llround(static_cast<double>(k) * 1e9 / rate_hz_));
  };
  int64_t due = start_pace_ns_ + due_after_start(index_);
  int64_t now = pace_now();
  // A long stall, or simulated time going back (a looped bag), restarts the schedule from now.
  // Back means before the last frame's due instant, which time had reached to release it (a
  // rosbag --loop returns to exactly the bag's start, where the schedule may have started too).
  const int64_t last_due = start_pace_ns_ + due_after_start(std::max<int64_t>(index_ - 1, 0));
  if (now - due > kMaxLagNs || (simulated && now < last_due)) {
    start_ros_ns_ = simulated ? now : start_ros_ns_ + (now - start_pace_ns_);
    start_pace_ns_ = now;
    index_ = 0;
    due = now;
  }
  if (due > now) {
    // Simulated time may run slower than the sleep: then not due yet, and the caller asks again.
    // Or faster (rosbag play -r 10): a wait of ROS time slept as wall time woke 10 times too late,
    // past kMaxLagNs at 10 fps, and every frame restarted the schedule; so it is slept in slices.
    const int64_t wait = std::min(due - now, max_wait_ns);
    clock_->SleepNs(simulated ? std::min(wait, kNoClockPollNs) : wait);
    now = pace_now();
    if (now < due) return false;
  }
  // Outside simulated time the stamps are wall time read once and carried on by the monotonic
  // clock: a source started before NTP stepped the wall clock back 2 min stamped every frame
  // 120 s ahead, and clip_buffer refused them all (~max_future) for as long as it ran.
  if (!simulated) {
    const int64_t step = clock_->RosNs() - (start_ros_ns_ + (now - start_pace_ns_));
    if (std::abs(step) > kMaxClockStepNs) start_ros_ns_ += step;
  }
  *stamp_ns = start_ros_ns_ + (due - start_pace_ns_);
  ++index_;
  return true;
}

void PacedFrameSlot::Fill(Frame frame) {
  frame_ = std::move(frame);
  frame_valid_ = true;
}

void PacedFrameSlot::FillBad() { bad_ = true; }

void PacedFrameSlot::Clear() { frame_valid_ = bad_ = false; }

ReadStatus PacedFrameSlot::ReleaseWhenDue(FramePacer* pacer, double max_wait_s, Frame* frame) {
  int64_t stamp = 0;
  if (!pacer->WaitNext(max_wait_s, &stamp)) return ReadStatus::kNoFrame;
  if (bad_) {
    bad_ = false;
    return ReadStatus::kBadFrame;
  }
  *frame = std::move(frame_);
  frame->stamp_ns = stamp;
  frame_valid_ = false;
  return ReadStatus::kFrame;
}

}  // namespace sensors
}  // namespace clothwind
