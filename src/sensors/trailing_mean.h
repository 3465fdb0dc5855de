// The mean of the wind estimates over a trailing time window: what a clip-by-clip estimate is
// compared with in the field, where the anemometer's label is its mean over the last minute.
// ROS-free; used by sdn_node (`wind/estimate_mean`) and the replay report (estimate_report.h).
#ifndef CLOTHWIND_SENSORS_TRAILING_MEAN_H_
#define CLOTHWIND_SENSORS_TRAILING_MEAN_H_

#include <cstddef>
#include <cstdint>
#include <deque>

namespace clothwind::sensors {

class TrailingMean {
 public:
  // window [s] > 0: a value added at time t stays in the mean while the newest time is < t + window,
  // i.e. the window is (newest - window, newest]. Throws std::invalid_argument otherwise.
  explicit TrailingMean(double window);

  // Adds `value` (with its standard deviation `std`, NaN if none) at time t [s]. A non-finite value
  // is left out of the mean but still moves the window on. A t earlier than the newest (a replay
  // that loops, a clock that jumped back) starts the window afresh and counts a restart.
  // `tag` is carried with the entry and read back by OldestTag (sdn_node: the clip's first frame
  // stamp in nanoseconds, which a double of seconds would round).
  void Add(double t, double value, double std = 0.0, std::uint64_t tag = 0);

  // Values in the window (finite ones only).
  std::size_t Count() const { return count_; }
  // Their mean; NaN when Count() == 0.
  double Mean() const;
  // The root mean of their variances (NaN if any value came without a finite std): the std of one
  // estimate in the window, not divided by sqrt(Count()) because successive clips show the same
  // gusts and flapping, so their errors are far from independent.
  double Std() const;
  // Time of the oldest entry still in the window (finite value or not); NaN when empty.
  double Oldest() const;
  // The tag given with that entry; 0 when empty.
  std::uint64_t OldestTag() const;
  // Times Add started the window afresh because time went back.
  std::size_t Restarts() const { return restarts_; }
  double window() const { return window_; }

 private:
  struct Entry {
    double t, value, var;
    std::uint64_t tag;
  };
  double window_;
  std::deque<Entry> entries_;
  std::size_t count_ = 0;   // finite values in entries_
  std::size_t no_std_ = 0;  // finite values without a finite std
  std::size_t restarts_ = 0;
  double sum_ = 0, sum_var_ = 0;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_TRAILING_MEAN_H_
