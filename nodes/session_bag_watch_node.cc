// session_bag_watch: the session recorder's health in /diagnostics (field.launch bag:=true runs it
// beside `rosbag record`, which publishes none): the bag being written, its size and write rate,
// the free space of its disk and the time left to fill it, bags begun and closed this session, and
// bags a killed recorder left open (sensors/session_bag_watch.h).
// Parameters: ~bag_prefix (rosbag record's -o, absolute: /data/session), ~stall_after (10 s: a bag
// not growing longer is an ERROR), ~min_free_bytes (2e9: less free is a WARN), ~min_time_to_full
// (600 s: a disk full sooner at the write rate is a WARN). Published every wall second
// (~diagnostic_period); a parameter of the wrong type or out of range ends the node with a FATAL.
#include <cmath>
#include <string>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_diagnostics.h"
#include "sensors/session_bag_watch.h"

namespace {

class SessionBagWatchNode {
 public:
  // Throws ParamError or std::invalid_argument for a parameter it cannot take (main ends on it).
  SessionBagWatchNode(ros::NodeHandle& nh, clothwind::ros_bridge::StrictParams& params)
      : watch_(Watch(params)) {
    updater_.setHardwareID("bag:" + params.Get("bag_prefix", ""));
    updater_.add("session bag", this, &SessionBagWatchNode::Diagnose);
    timer_ = nh.createSteadyTimer(ros::WallDuration(clothwind::ros_bridge::DiagnosticPeriod(updater_)),
                                  [this](const ros::SteadyTimerEvent&) {
                                    clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);
                                  });
    clothwind::ros_bridge::ForceDiagnosticUpdate(updater_);
  }

 private:
  // The watch, its options' errors named as parameters.
  static clothwind::sensors::SessionBagWatch Watch(clothwind::ros_bridge::StrictParams& params) {
    try {
      return clothwind::sensors::SessionBagWatch(Options(params));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("a parameter: ") + e.what() +
                                  " (~stall_after, ~min_free_bytes, ~min_time_to_full)");
    }
  }

  static clothwind::sensors::SessionBagWatch::Options Options(clothwind::ros_bridge::StrictParams& params) {
    clothwind::sensors::SessionBagWatch::Options o;
    o.prefix = params.Get("bag_prefix", "");
    if (o.prefix.empty() || o.prefix[0] != '/')
      throw std::invalid_argument("~bag_prefix must be rosbag record's -o as an absolute path (/data/session), got \"" +
                                  o.prefix + "\"");
    o.stall_after = params.Get("stall_after", o.stall_after);
    const double min_free = params.Get("min_free_bytes", static_cast<double>(o.min_available));
    if (!(min_free >= 0 && min_free < 1e19)) throw std::invalid_argument("~min_free_bytes must be >= 0");
    o.min_available = static_cast<uint64_t>(min_free);
    o.min_seconds_to_full = params.Get("min_time_to_full", o.min_seconds_to_full);  // checked by the watch
    return o;
  }

  void Diagnose(diagnostic_updater::DiagnosticStatusWrapper& stat) {
    using Level = clothwind::sensors::SessionBagReport::Level;
    const clothwind::sensors::SessionBagReport r = watch_.Poll(ros::SteadyTime::now().toSec());
    stat.summary(r.level == Level::kOk     ? diagnostic_msgs::DiagnosticStatus::OK
                 : r.level == Level::kWarn ? diagnostic_msgs::DiagnosticStatus::WARN
                                           : diagnostic_msgs::DiagnosticStatus::ERROR,
                 r.message);
    stat.add("bag", r.bag.empty() ? std::string("none") : r.bag);
    stat.add("size [MB]", r.bag_bytes / 1e6);
    stat.add("write rate [MB/s]", r.write_rate / 1e6);
    stat.add("seconds since it grew", r.seconds_since_growth);
    stat.add("free space [GB]", r.available / 1e9);
    stat.add("time to fill the disk [s]", r.seconds_to_full);
    stat.add("bags begun this session", r.bags_started);
    stat.add("bags closed this session", r.bags_closed);
    std::string open;
    for (const std::string& b : r.left_open) open += (open.empty() ? "" : ", ") + b;
    stat.add("bags left open (rosbag reindex them)", open.empty() ? std::string("none") : open);
  }

  clothwind::sensors::SessionBagWatch watch_;
  diagnostic_updater::Updater updater_;
  ros::SteadyTimer timer_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "session_bag_watch");
  // Held outside the try: the last NodeHandle going out of scope shuts ROS down, and the FATAL
  // naming a bad parameter was then never printed.
  ros::NodeHandle nh, pnh("~");
  clothwind::ros_bridge::StrictParams params(pnh);
  try {
    clothwind::ros_bridge::CheckDiagnosticPeriod(params);  // before the node's diagnostic_updater reads it
    SessionBagWatchNode node(nh, params);
    params.WarnUnread("session_bag_watch");
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("session_bag_watch: %s", e.what());
    return 1;
  }
  return 0;
}
