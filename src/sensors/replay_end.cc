#include "sensors/replay_end.h"

#include <algorithm>

namespace clothwind::sensors {

ReplayEnd::ReplayEnd(const ReplayEndOptions& options, double wall)
    : options_(options), start_(wall), last_change_(wall) {}

void ReplayEnd::Clock(double clock, double wall) {
  if (clock != last_clock_) {
    last_clock_ = clock;
    last_change_ = wall;
    started_ = started_ || clock != 0.0;
  }
}

void ReplayEnd::Estimate(double wall) {
  if (estimates_++ > 0) longest_estimate_gap_ = std::max(longest_estimate_gap_, wall - last_estimate_);
  last_estimate_ = last_change_ = wall;
}

ReplayVerdict ReplayEnd::Check(double wall, std::size_t unestimated) const {
  const double ran = wall - start_, idle = wall - last_change_;
  if (!started_ && ran > options_.start_timeout) return ReplayVerdict::kNoClock;
  const double wait = estimates_ < 2 ? options_.estimate_wait
                                     : std::min(options_.estimate_wait, 2.0 * longest_estimate_gap_);
  const double limit = options_.idle_timeout + (unestimated > 0 ? wait : 0.0);
  if (started_ && idle > limit) return ReplayVerdict::kOver;
  if (options_.max_wall > 0 && ran > options_.max_wall) return ReplayVerdict::kMaxWall;
  return ReplayVerdict::kRunning;
}

}  // namespace clothwind::sensors
