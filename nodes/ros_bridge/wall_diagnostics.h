// Diagnostics published once a wall second whatever ROS time does. Why: Updater::update() waits
// for ROS time to pass its next due time, and under use_sim_time ROS time does not run before
// /clock and never again passes a looped or ended bag's old end: anemometer_node and camera_node
// then published no diagnostics at all (a WARN about the missing /clock included).
#ifndef CLOTHWIND_NODES_ROS_BRIDGE_WALL_DIAGNOSTICS_H_
#define CLOTHWIND_NODES_ROS_BRIDGE_WALL_DIAGNOSTICS_H_

#include <cmath>
#include <sstream>

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/console.h>
#include <ros/node_handle.h>
#include <ros/time.h>

#include "ros_bridge/strict_param.h"
#include "ros_bridge/wall_throttle.h"

namespace clothwind::ros_bridge {

// What ~diagnostic_period may be: a time in (0, 3600] s.
inline bool DiagnosticPeriodIsValid(double period) { return std::isfinite(period) && period > 0 && period <= 3600; }

// Reads ~diagnostic_period (counting it as read) before a diagnostic_updater::Updater does, and
// throws ParamError naming it unless it is unset or valid. The Updater turns it into a
// ros::Duration, which throws "Duration is out of dual 32-bit range", naming no parameter, for
// NaN, inf or more than 2^31 s, in its constructor and again in every force_update: three nodes
// ended in std::terminate on `_diagnostic_period:=1e10`, and camera_node's respawn looped on it.
// Call it before constructing any Updater.
inline void CheckDiagnosticPeriod(StrictParams& params) {
  const double period = params.Get("diagnostic_period", 1.0);
  if (!DiagnosticPeriodIsValid(period)) {
    std::ostringstream what;
    what << "~diagnostic_period: expected a time in (0, 3600] s, got " << period;
    throw ParamError(what.str());
  }
}

// The period [s] diagnostic_updater read from ~diagnostic_period (1 s unset). The nodes publish
// on wall timers of their own, which ran every second whatever it said: `_diagnostic_period:=10`
// was accepted and did nothing. Checked at start (CheckDiagnosticPeriod); a value set while the
// node runs that is not valid: 1 s, said once.
inline double DiagnosticPeriod(diagnostic_updater::Updater& updater) {
  const double period = updater.getPeriod();
  if (DiagnosticPeriodIsValid(period)) return period;
  ROS_WARN_STREAM("~diagnostic_period must be a time in (0, 3600] s, got " << period << ": 1 s used");
  return 1.0;
}

// updater.force_update(), keeping ~diagnostic_period valid first. Why: force_update re-reads the
// parameter (cached, so a `rosparam set` reaches it) into a ros::Duration, which throws for NaN,
// inf or more than 2^31 s: `rosparam set /wind_display/diagnostic_period 1.0e+10` ended a running
// node with "Duration is out of dual 32-bit range", naming no parameter. A value out of (0, 3600] s
// is refused with an ERROR naming it, and the parameter is set back to the period in use (what
// the updater read last, valid: checked at start and before every read since).
inline void ForceDiagnosticUpdate(diagnostic_updater::Updater& updater) {
  ros::NodeHandle private_nh("~");  // the Updater's own: diagnostic_updater reads "~diagnostic_period"
  double period = 0;
  if (private_nh.getParamCached("diagnostic_period", period) && !DiagnosticPeriodIsValid(period)) {
    const double in_use = updater.getPeriod();
    ROS_ERROR_STREAM("~diagnostic_period: expected a time in (0, 3600] s, got " << period << "; set back to the "
                     << in_use << " s in use");
    private_nh.setParam("diagnostic_period", in_use);  // roscpp updates its cache of the key too
  }
  updater.force_update();
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
    if (throttle_.Due(period_)) ForceDiagnosticUpdate(*updater_);
  }

 private:
  diagnostic_updater::Updater* updater_;
  double period_;
  WallThrottle throttle_;
};

}  // namespace clothwind::ros_bridge

#endif  // CLOTHWIND_NODES_ROS_BRIDGE_WALL_DIAGNOSTICS_H_
