// When a replayed session is over, for the report over it (clip_report_node): rosbag play --clock
// gives no end-of-bag signal, so the end is read from the clock standing still. ROS-free, in wall
// and clock seconds, so the rule is tested without a replay.
#ifndef CLOTHWIND_SENSORS_REPLAY_END_H_
#define CLOTHWIND_SENSORS_REPLAY_END_H_

#include <cstddef>

namespace clothwind::sensors {

struct ReplayEndOptions {
  double idle_timeout = 5.0;    // [s, wall] the clock and the inputs still this long: over
  double estimate_wait = 60.0;  // [s, wall] at most this much longer while clips lack their estimate
  double max_wall = 0.0;        // [s, wall] over after this long anyway; 0: no bound
  double start_timeout = 60.0;  // [s, wall] the clock never started this long: give up
};

enum class ReplayVerdict {
  kRunning,   // not over
  kOver,      // the clock and the inputs stood still long enough: the replay has ended
  kMaxWall,   // cut at max_wall, the replay perhaps still running
  kNoClock,   // the clock never started (a player waiting for a subscriber that died)
};

class ReplayEnd {
 public:
  // Inputs: options (times >= 0; idle_timeout and start_timeout > 0); wall  [s] now, the start.
  ReplayEnd(const ReplayEndOptions& options, double wall);

  // The clock read at wall time `wall` (0: not started, as ROS time before /clock). A change
  // counts as activity.
  void Clock(double clock, double wall);
  // A clip came at wall time `wall`.
  void Activity(double wall) { last_change_ = wall; }
  // A /clock message came at wall time `wall`: the player runs, perhaps paused (rosbag play keeps
  // publishing its clock, unchanged, while paused; it stops when the player exits). Activity once
  // the clock has started: a pause of idle_timeout ended the replay and printed its report.
  void Player(double wall) {
    if (started_) last_change_ = wall;
  }
  // An estimate came at wall time `wall`: activity, and the model's pace.
  void Estimate(double wall);

  // Whether the replay is over at wall time `wall`, with `unestimated` clips still lacking their
  // estimate (0 without a model): idle for idle_timeout, and while some lack one, longer by
  // twice the longest wait between two estimates so far (sdn_node working through its queue: a
  // model slower than idle_timeout a clip had its backlog cut off), estimate_wait before two
  // estimates have come and at most. A fast model's refused clips (malformed, no model yet) so
  // cost seconds, not a minute.
  ReplayVerdict Check(double wall, std::size_t unestimated) const;

  const ReplayEndOptions& options() const { return options_; }

 private:
  ReplayEndOptions options_;
  double start_, last_change_, last_clock_ = 0.0;
  double last_estimate_ = 0.0, longest_estimate_gap_ = 0.0;
  int estimates_ = 0;
  bool started_ = false;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_REPLAY_END_H_
