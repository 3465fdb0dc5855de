#include "sensors/clock_course.h"

#include <algorithm>
#include <cmath>

namespace clothwind::sensors {

void ClockCourse::Note(double now, double jump) {
  if (!std::isfinite(now)) return;  // no clock yet
  if (now < high_ - jump) {
    before_jump_ = high_;
    high_ = now;
  } else {
    high_ = std::max(high_, now);
  }
  if (now > before_jump_) before_jump_ = -std::numeric_limits<double>::infinity();
}

}  // namespace clothwind::sensors
