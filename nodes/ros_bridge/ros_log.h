// The core's log lines (sensors::LogFn: a frame source's, the clip recording's) into ROS's log at
// their level, and a node's last words after ROS has shut down.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_ROS_LOG_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_ROS_LOG_H_

#include <cstdio>
#include <string>

#include <ros/console.h>
#include <ros/init.h>
#include <ros/time.h>

#include "sensors/frame_source.h"

namespace clothwind::ros_bridge {

// Whether rosconsole still prints. Ctrl-C (or `rosnode kill`) ends ros::spin() through
// ros::shutdown(), which shuts rosconsole down with it: every ROS_* line after it printed nothing,
// on the screen or /rosout, so what a node said once spin() returned (the clips the clip buffer
// gave up, by name; a summary clip_report could not write, with its exit status 1) was lost.
// (Also false between ros::init and the first NodeHandle, when rosconsole works: lines there go to
// stderr too, in its format. Every node makes its NodeHandle before logging.)
inline bool RosConsoleUp() { return ros::ok() && !ros::isShuttingDown(); }

// Inputs: severity  "INFO", "WARN", "ERROR" or "FATAL"; message.
// Writes one line to stderr in rosconsole's screen format ("[ERROR] [1700000000.123456]: ..."),
// flushed: roslaunch keeps a node's stderr in its log and on the screen with output="screen".
inline void StderrLogLine(const char* severity, const std::string& message) {
  std::fprintf(stderr, "[%s] [%.6f]: %s\n", severity, ros::WallTime::now().toSec(), message.c_str());
  std::fflush(stderr);
}

// Inputs: level, message (logged as it is; a node adds its own prefix before calling).
// Logged through rosconsole while it is up, else to stderr (StderrLogLine).
inline void RosLog(sensors::LogLevel level, const std::string& message) {
  if (!RosConsoleUp()) {
    StderrLogLine(level == sensors::LogLevel::kInfo   ? "INFO"
                  : level == sensors::LogLevel::kWarn ? "WARN"
                                                      : "ERROR",
                  message);
    return;
  }
  switch (level) {
    case sensors::LogLevel::kInfo: ROS_INFO_STREAM(message); break;
    case sensors::LogLevel::kWarn: ROS_WARN_STREAM(message); break;
    case sensors::LogLevel::kError: ROS_ERROR_STREAM(message); break;
  }
}

// A FATAL, also after ROS has shut down (a node's Finish failing once spin() returned).
inline void RosFatal(const std::string& message) {
  if (RosConsoleUp()) {
    ROS_FATAL_STREAM(message);
  } else {
    StderrLogLine("FATAL", message);
  }
}

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_ROS_LOG_H_
