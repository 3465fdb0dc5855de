// The rate at which an instrument's readings arrive, for diagnostics: readings over a trailing
// window, so an instrument that falls silent reads slower as its readings age out (readings over
// their own span kept its last rate for ever). ROS-free; anemometer_node reports it.
#ifndef CLOTHWIND_SENSORS_READING_RATE_H_
#define CLOTHWIND_SENSORS_READING_RATE_H_

#include <cstddef>
#include <deque>

namespace clothwind::sensors {

class ReadingRate {
 public:
  // max_kept: the most arrival times kept (a fast instrument over a long window).
  explicit ReadingRate(std::size_t max_kept = 4096) : max_kept_(max_kept) {}

  // A reading arrived at time t [s] (any clock: a replay's ROS time, or the monotonic clock). A t
  // before the last one (the clock went back: a looped replay) starts afresh.
  void Add(double t);

  // Readings per second at time now [s] over [now - window, now] (window [s] > 0), or, before the
  // window has passed since the first reading, (count - 1) over the time since it (0 with fewer
  // than 2). Forgets readings older than the window, and those after now (a clock gone back).
  double Rate(double now, double window);

 private:
  std::size_t max_kept_;
  std::deque<double> times_;
  double first_ = 0.0;  // the first reading's time (> 0) since the clock last went back; 0: none
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_READING_RATE_H_
