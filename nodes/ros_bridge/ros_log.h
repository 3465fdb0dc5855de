// The core's log lines (sensors::LogFn: a frame source's, the clip recording's) into ROS's log at
// their level.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_ROS_LOG_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_ROS_LOG_H_

#include <string>

#include <ros/console.h>

#include "sensors/frame_source.h"

namespace clothwind::ros_bridge {

// Inputs: level, message (logged as it is; a node adds its own prefix before calling).
inline void RosLog(sensors::LogLevel level, const std::string& message) {
  switch (level) {
    case sensors::LogLevel::kInfo: ROS_INFO_STREAM(message); break;
    case sensors::LogLevel::kWarn: ROS_WARN_STREAM(message); break;
    case sensors::LogLevel::kError: ROS_ERROR_STREAM(message); break;
  }
}

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_ROS_LOG_H_
