#include "sensors/display_clock.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace clothwind::sensors {
namespace {
// As ros::Time::toSec() rounds (whole seconds plus nanoseconds), so a stamp exactly max_future
// ahead is judged as the node judged it before this class ((double)ns * 1e-9 rounds some up).
double Seconds(std::uint64_t ns) {
  return static_cast<double>(ns / 1000000000ull) + 1e-9 * static_cast<double>(ns % 1000000000ull);
}
}  // namespace

DisplayClock::DisplayClock(int inputs, double max_future, double restart_after)
    : max_future_(max_future),
      restart_after_(restart_after),
      clock_before_restart_(-std::numeric_limits<double>::infinity()) {
  if (inputs < 1) throw std::invalid_argument("DisplayClock: inputs must be >= 1");
  if (!(max_future > 0) || !std::isfinite(max_future) || !(restart_after > 0) || !std::isfinite(restart_after)) {
    throw std::invalid_argument("DisplayClock: max_future and restart_after must be finite and > 0 s");
  }
  newest_.assign(inputs, 0);
}

bool DisplayClock::CheckClock(std::uint64_t now_ns) {
  const double clock = Seconds(now_ns);
  bool restarted = false;
  if (clock > 0 && last_clock_ > 0 && clock + restart_after_ < last_clock_) {
    Restart(std::max(last_clock_, Seconds(NewestOfAll())));
    restarted = true;
  }
  if (clock > 0) last_clock_ = clock;
  return restarted;
}

DisplayClock::Verdict DisplayClock::Admit(int input, std::uint64_t stamp_ns, std::uint64_t now_ns, bool* restarted) {
  // A new pass's first message may come before the display's next tick notices the clock's jump.
  *restarted = CheckClock(now_ns);
  if (stamp_ns == 0) return Verdict::kUnstamped;
  const double now = Seconds(now_ns), t = Seconds(stamp_ns);
  if (now > 0 && t > now + max_future_) {
    // Stamped before the clock last went back: the previous pass's, not a clock fault.
    return t <= clock_before_restart_ + max_future_ ? Verdict::kPreviousPass : Verdict::kFuture;
  }
  const double newest = Seconds(newest_.at(input));
  if (t + restart_after_ < newest) {
    // The replay restarted when the clock went back too (or has not started); otherwise this one
    // message is late, and wiping the display for it would be wrong.
    if (now > 0 && now + restart_after_ >= newest) return Verdict::kLate;
    Restart(std::max(newest, last_clock_));
    *restarted = true;
  }
  newest_[input] = std::max(newest_[input], stamp_ns);
  return Verdict::kShow;
}

std::uint64_t DisplayClock::DisplayNow(std::uint64_t now_ns) const {
  const std::uint64_t latest = NewestOfAll();
  if (now_ns == 0 || Seconds(now_ns) + restart_after_ < Seconds(latest)) return latest;
  return std::max(now_ns, latest);
}

std::uint64_t DisplayClock::NewestOfAll() const { return *std::max_element(newest_.begin(), newest_.end()); }

void DisplayClock::Restart(double previous_end) {
  std::fill(newest_.begin(), newest_.end(), 0);
  clock_before_restart_ = previous_end;
  ++restarts_;
}

}  // namespace clothwind::sensors
