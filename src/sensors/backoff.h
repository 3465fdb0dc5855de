// Retry delays for opening a device: short first (a udev symlink appearing), doubling up to a
// ceiling (a device unplugged for long stretches is not polled without pause). ROS-free;
// anemometer_node reopens its serial port and USB station with it, camera_node its source.
#ifndef CLOTHWIND_SENSORS_BACKOFF_H_
#define CLOTHWIND_SENSORS_BACKOFF_H_

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace clothwind::sensors {

class Backoff {
 public:
  // initial, maximum [s]: finite, 0 < initial <= maximum. Throws std::invalid_argument otherwise.
  Backoff(double initial, double maximum) : initial_(initial), max_(maximum), delay_(initial) {
    if (!(initial > 0) || !(maximum >= initial) || !std::isfinite(maximum))
      throw std::invalid_argument("Backoff: expected finite delays with 0 < initial <= maximum");
  }
  // After a success: the next failure waits `initial` again.
  void Reset() { delay_ = initial_; }
  // The delay before the next attempt [s]: initial, 2 initial, 4 initial, ... up to maximum.
  double Next() {
    const double d = delay_;
    delay_ = std::min(delay_ * 2.0, max_);
    return d;
  }

 private:
  double initial_, max_, delay_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_BACKOFF_H_
