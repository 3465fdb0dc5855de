// Where the clock has been, to tell a replay's previous pass from a clock set wrong. A looped
// bag's /clock goes back to the bag's start while messages of the previous pass are still in
// flight (queued in subscribers), stamped up to where the clock was: ahead of the new clock, but
// not from the future. ROS-free, in seconds of any clock.
#ifndef CLOTHWIND_SENSORS_CLOCK_COURSE_H_
#define CLOTHWIND_SENSORS_CLOCK_COURSE_H_

#include <limits>

namespace clothwind::sensors {

class ClockCourse {
 public:
  // The clock read `now` [s]. Back by more than `jump` [s] from the latest time it showed is a
  // jump back; where it was is remembered until it passes that point again.
  void Note(double now, double jump = 1.0);

  // Whether a message stamped `stamp` [s], ahead of the clock by more than `max_future` [s], is
  // the previous pass's: not past where the clock was before it last went back (plus max_future).
  bool IsPreviousPass(double stamp, double max_future) const {
    return stamp <= before_jump_ + max_future;
  }

  double latest() const { return high_; }                // the latest time shown since the last jump
  double before_last_jump() const { return before_jump_; }  // -inf: none pending

 private:
  double high_ = -std::numeric_limits<double>::infinity();
  double before_jump_ = -std::numeric_limits<double>::infinity();
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CLOCK_COURSE_H_
