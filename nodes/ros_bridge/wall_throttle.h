// Throttled logging by the wall clock. Why: ROS_*_THROTTLE measures its period in ROS time, which
// under use_sim_time stands at 0 before /clock (the first message's check, 0 + period <= 0, never
// passes, so "cannot open ... (retrying)" was never printed while the bag had not started) and
// stands still after a bag ends. A node's complaints about its device or input should reach the
// console whatever the clock does.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_WALL_THROTTLE_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_WALL_THROTTLE_H_

#include <ros/console.h>
#include <ros/time.h>

namespace clothwind::ros_bridge {

// One throttled call site: Due() is true on the first call and then at most once per `period`
// wall seconds (and again at once should the wall clock step back).
class WallThrottle {
 public:
  bool Due(double period) { return DueAt(ros::WallTime::now().toSec(), period); }
  // The same at a given wall time [s], for tests.
  bool DueAt(double now, double period) {
    if (fired_ && now >= last_ && now < last_ + period) return false;
    fired_ = true;
    last_ = now;
    return true;
  }

 private:
  bool fired_ = false;
  double last_ = 0;
};

}  // namespace clothwind::ros_bridge

// As ROS_<LEVEL>_THROTTLE and ROS_<LEVEL>_STREAM_THROTTLE, timed by the wall clock.
#define CLOTHWIND_LOG_WALL_THROTTLE(period, level, ...)                      \
  do {                                                                       \
    static ::clothwind::ros_bridge::WallThrottle clothwind_wall_throttle_;  \
    if (clothwind_wall_throttle_.Due(period)) ROS_LOG(level, ROSCONSOLE_DEFAULT_NAME, __VA_ARGS__); \
  } while (false)
#define CLOTHWIND_LOG_STREAM_WALL_THROTTLE(period, level, args)              \
  do {                                                                       \
    static ::clothwind::ros_bridge::WallThrottle clothwind_wall_throttle_;  \
    if (clothwind_wall_throttle_.Due(period)) ROS_LOG_STREAM(level, ROSCONSOLE_DEFAULT_NAME, args); \
  } while (false)
#define WALL_WARN_THROTTLE(period, ...) \
  CLOTHWIND_LOG_WALL_THROTTLE(period, ::ros::console::levels::Warn, __VA_ARGS__)
#define WALL_ERROR_THROTTLE(period, ...) \
  CLOTHWIND_LOG_WALL_THROTTLE(period, ::ros::console::levels::Error, __VA_ARGS__)
#define WALL_WARN_STREAM_THROTTLE(period, args) \
  CLOTHWIND_LOG_STREAM_WALL_THROTTLE(period, ::ros::console::levels::Warn, args)
#define WALL_ERROR_STREAM_THROTTLE(period, args) \
  CLOTHWIND_LOG_STREAM_WALL_THROTTLE(period, ::ros::console::levels::Error, args)

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_WALL_THROTTLE_H_
