#ifndef CLOTHWIND_SENSORS_FRAME_TIMESTAMP_H_
#define CLOTHWIND_SENSORS_FRAME_TIMESTAMP_H_

#include <cstdint>
#include <deque>
#include <utility>

namespace clothwind {
namespace sensors {

// The clocks the capture path reads. Injected so tests can run a driver emulation in fake time
// and nodes can substitute ROS time for the wall clock.
class Clock {
 public:
  virtual ~Clock() = default;
  // CLOCK_MONOTONIC now [ns]: the clock V4L2 drivers stamp buffers with.
  virtual int64_t MonotonicNs() = 0;
  // ROS time now [ns since the Unix epoch]; the wall clock (CLOCK_REALTIME) by default.
  virtual int64_t RosNs() = 0;
  // Blocks for duration_ns [ns] (a fake clock advances instead). Non-positive: returns at once.
  virtual void SleepNs(int64_t duration_ns) = 0;
  // Whether ROS time is simulated (use_sim_time: /clock from rosbag play --clock), so that it may
  // run slower or faster than the monotonic clock, stop, start at 0 or jump back.
  virtual bool RosTimeIsSimulated() { return false; }
};

// The real clocks: CLOCK_MONOTONIC, CLOCK_REALTIME, nanosleep.
class SystemClock : public Clock {
 public:
  int64_t MonotonicNs() override;
  int64_t RosNs() override;
  void SleepNs(int64_t duration_ns) override;
};

// Estimates offset = ros - source between two clocks from pairs (source_ns, ros_ns) where ros_ns
// was read at or after the instant source_ns denotes. Any delay between the two (scheduling,
// USB transfer, a preempted thread) only makes a sample's offset larger, so the minimum over
// the recent samples is the least-delayed estimate. The window is finite so clock drift and
// steps of the ROS clock are followed (a backward step at once, a forward one after `window`
// samples).
class ClockOffsetEstimator {
 public:
  // Inputs:
  //   window  number of most recent samples the minimum is taken over (>= 1)
  explicit ClockOffsetEstimator(int window = 100);

  // Adds one sample.
  // Inputs:
  //   source_ns  an instant in the source clock [ns]
  //   ros_ns     ROS time read at (or after) that instant [ns]
  void AddSample(int64_t source_ns, int64_t ros_ns);

  // True once a sample has been added since construction/Reset.
  bool HasEstimate() const { return !window_min_.empty(); }

  // Current estimate of ros - source [ns]: minimum offset over the window. 0 without samples.
  int64_t OffsetNs() const { return window_min_.empty() ? 0 : window_min_.front().second; }

  // Forgets all samples (e.g. after the device was reopened on another clock).
  void Reset();

 private:
  int window_;
  int64_t count_ = 0;
  // Monotone deque for the sliding-window minimum: (sample index, offset), offsets increasing.
  std::deque<std::pair<int64_t, int64_t>> window_min_;
};

// Which clock a driver's buffer timestamps are in.
enum class DriverClock {
  kMonotonic,  // V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC: CLOCK_MONOTONIC at capture (start of frame)
  kUnknown,    // V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN/COPY or anything else: an unrelated clock
};

// Maps driver buffer timestamps to ROS time, so a frame carries the time it was captured and not
// the time it happened to be dequeued or published.
//  - kMonotonic: the driver stamps CLOCK_MONOTONIC, so only the monotonic->ROS offset is needed.
//    It is sampled at every frame by reading both clocks back to back; the minimum over recent
//    samples drops the samples where the thread was preempted between the two reads.
//  - kUnknown: the offset between the driver clock and ROS time is estimated from the dequeue
//    time; its minimum over recent frames is the smallest capture-to-dequeue latency, which is
//    as close to the capture instant as the data allows (it still includes that latency).
//  - A zero driver stamp (drivers that do not stamp) falls back to the dequeue time.
class FrameTimestamper {
 public:
  // Inputs:
  //   clock   clocks to read (not owned; must outlive this)
  //   window  samples the offset minimum is taken over
  FrameTimestamper(Clock* clock, int window = 100);

  // Maps one buffer timestamp.
  // Inputs:
  //   driver_ns  v4l2_buffer.timestamp [ns]
  //   kind       the clock it is in
  // Returns the capture time in ROS time [ns since the Unix epoch].
  int64_t Map(int64_t driver_ns, DriverClock kind);

  // Current offset ROS - driver clock [ns] (0 before the first frame).
  int64_t OffsetNs() const { return estimator_.OffsetNs(); }

  // Forgets the offset (call when the device is reopened).
  void Reset();

 private:
  Clock* clock_;
  ClockOffsetEstimator estimator_;
  bool have_kind_ = false;
  DriverClock kind_ = DriverClock::kMonotonic;
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_FRAME_TIMESTAMP_H_
