// A boolean node parameter that also takes 1 / 0: `_loop:=1` on a command line (or `1` in YAML)
// arrives as an int, which NodeHandle::param(bool) silently refuses, leaving the default.
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_BOOL_PARAM_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_BOOL_PARAM_H_

#include <stdexcept>
#include <string>

#include <ros/ros.h>

namespace clothwind::ros_bridge {

// Inputs:
//   pnh       the node's private handle
//   name      parameter name (without "~")
//   fallback  the value when the parameter is not set
// Returns the parameter as a bool. Throws std::invalid_argument naming "~name" when it is set to
// anything but true, false, 1 or 0.
inline bool BoolParam(const ros::NodeHandle& pnh, const std::string& name, bool fallback) {
  if (!pnh.hasParam(name)) return fallback;
  XmlRpc::XmlRpcValue v;
  pnh.getParam(name, v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) return static_cast<bool>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt && (static_cast<int>(v) == 0 || static_cast<int>(v) == 1))
    return static_cast<int>(v) == 1;
  throw std::invalid_argument("~" + name + " must be true/false or 1/0, got " + v.toXml());
}

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_BOOL_PARAM_H_
