#include "sensors/reading_rate.h"

namespace clothwind::sensors {

void ReadingRate::Add(double t) {
  const bool back = !times_.empty() && t < times_.back();  // the clock went back
  if (back) times_.clear();
  // A reading stamped 0 (topic input before a replay's /clock) is no first time: the rate would
  // read over the whole time since 0 once the clock starts. After the clock went back the first
  // time is this reading's, also when it is later than the old first one.
  if (back || (times_.empty() && (first_ <= 0 || t < first_))) first_ = t;
  times_.push_back(t);
  if (times_.size() > max_kept_) times_.pop_front();
}

double ReadingRate::Rate(double now, double window) {
  while (!times_.empty() && (now - times_.front() > window || now < times_.front())) times_.pop_front();
  const double since_first = now - first_;
  const double n = static_cast<double>(times_.size());
  if (since_first >= window) return n / window;
  return n >= 2 && since_first > 0 ? (n - 1) / since_first : 0.0;
}

}  // namespace clothwind::sensors
