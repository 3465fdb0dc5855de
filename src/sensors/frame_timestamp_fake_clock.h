#ifndef CLOTHWIND_SENSORS_FRAME_TIMESTAMP_FAKE_CLOCK_H_
#define CLOTHWIND_SENSORS_FRAME_TIMESTAMP_FAKE_CLOCK_H_

#include <cstdint>

#include "sensors/frame_timestamp.h"

namespace clothwind {
namespace sensors {

// A Clock for tests: time only moves when told to (Advance, SleepNs, or a delay planted right
// after the next read of either clock, to imitate a thread preempted between two clock reads,
// whichever it reads first: a delay before the ROS read alone could not tell the order apart).
// ROS time = monotonic time + ros_offset_ns.
class FakeClock : public Clock {
 public:
  explicit FakeClock(int64_t start_monotonic_ns = 1000000000LL,
                     int64_t ros_offset_ns = 1700000000LL * 1000000000LL)
      : mono_ns_(start_monotonic_ns), ros_offset_ns_(ros_offset_ns) {}

  int64_t MonotonicNs() override {
    const int64_t now = mono_ns_;
    Preempt();
    return now;
  }
  int64_t RosNs() override {
    const int64_t now = mono_ns_ + ros_offset_ns_;
    Preempt();
    return now;
  }
  void SleepNs(int64_t duration_ns) override {
    if (duration_ns > 0) mono_ns_ += duration_ns;
    slept_ns_ += duration_ns > 0 ? duration_ns : 0;
  }

  void Advance(int64_t ns) { mono_ns_ += ns; }
  void StepRos(int64_t ns) { ros_offset_ns_ += ns; }  // the wall clock set (NTP), monotonic time unmoved
  void DelayAfterNextRead(int64_t ns) { after_next_read_ns_ = ns; }
  int64_t ros_offset_ns() const { return ros_offset_ns_; }
  int64_t slept_ns() const { return slept_ns_; }

 private:
  int64_t mono_ns_;
  int64_t ros_offset_ns_;
  int64_t after_next_read_ns_ = 0;
  void Preempt() {  // time passes once the read is done
    mono_ns_ += after_next_read_ns_;
    after_next_read_ns_ = 0;
  }
  int64_t slept_ns_ = 0;
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_FRAME_TIMESTAMP_FAKE_CLOCK_H_
