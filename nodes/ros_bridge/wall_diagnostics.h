// Diagnostics published once a wall second whatever ROS time does. Why: Updater::update() waits
// for ROS time to pass its next due time, and under use_sim_time ROS time does not run before
// /clock and never again passes a looped or ended bag's old end: anemometer_node and camera_node
// then published no diagnostics at all (a WARN about the missing /clock included).
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_WALL_DIAGNOSTICS_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_WALL_DIAGNOSTICS_H_

#include <cmath>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/console.h>
#include <ros/time.h>

#include "ros_bridge/wall_throttle.h"

namespace clothwind::ros_bridge {

// The period [s] diagnostic_updater read from ~diagnostic_period (1 s unset). The nodes publish
// on wall timers of their own, which ran every second whatever it said: `_diagnostic_period:=10`
// was accepted and did nothing. Not finite, <= 0 or over an hour: 1 s, said once.
inline double DiagnosticPeriod(diagnostic_updater::Updater& updater) {
  const double period = updater.getPeriod();
  if (std::isfinite(period) && period > 0 && period <= 3600) return period;
  ROS_WARN_STREAM("~diagnostic_period must be a time in (0, 3600] s, got " << period << ": 1 s used");
  return 1.0;
}

// Call Update() as often as convenient (each loop of a node's own spin); it publishes the
// updater's status when `period` wall seconds have passed since it last did.
class WallDiagnostics {
 public:
  explicit WallDiagnostics(diagnostic_updater::Updater* updater)
      : updater_(updater), period_(DiagnosticPeriod(*updater)) {}

  void Update() {
    // WallThrottle: due again at once should the wall clock step back (NTP), where a next-due
    // instant held every report until the clock caught up (an hour's step: an hour of silence).
    if (throttle_.Due(period_)) updater_->force_update();
  }

 private:
  diagnostic_updater::Updater* updater_;
  double period_;
  WallThrottle throttle_;
};

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_WALL_DIAGNOSTICS_H_
