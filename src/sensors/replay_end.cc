#include "sensors/replay_end.h"

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

ReplayVerdict ReplayEnd::Check(double wall, std::size_t unestimated) const {
  const double ran = wall - start_, idle = wall - last_change_;
  if (!started_ && ran > options_.start_timeout) return ReplayVerdict::kNoClock;
  const double limit = options_.idle_timeout + (unestimated > 0 ? options_.estimate_wait : 0.0);
  if (started_ && idle > limit) return ReplayVerdict::kOver;
  if (options_.max_wall > 0 && ran > options_.max_wall) return ReplayVerdict::kMaxWall;
  return ReplayVerdict::kRunning;
}

}  // namespace clothwind::sensors
