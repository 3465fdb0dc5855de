// When a live display of several stamped inputs (wind_display: the estimates and the anemometer's
// readings) may show a message, and what "now" it shows, on ROS time that may be a replay's: the
// clock can stand still (a paused bag), go back (a bag played again) or not have started. ROS-free;
// nodes/wind_display_node.cc converts stamps and keeps what is shown.
//
// Times are nanoseconds of ROS time, 0 meaning none (an unstamped message, a clock not started),
// so a stamp comes back exactly; the comparisons are in seconds.
#ifndef CLOTHWIND_SENSORS_DISPLAY_CLOCK_H_
#define CLOTHWIND_SENSORS_DISPLAY_CLOCK_H_

#include <cstdint>
#include <vector>

namespace clothwind::sensors {

class DisplayClock {
 public:
  enum class Verdict {
    kShow,          // show it (after forgetting what was shown, if Admit says it restarted)
    kUnstamped,     // stamp 0: it would stamp the displays 0 and empty the plot
    kFuture,        // more than max_future ahead of a running clock (a clock fault, or TIME_MAX)
    kPreviousPass,  // ahead of the clock, but of the pass before the clock went back (a queue's tail)
    kLate,          // more than restart_after behind its input's newest while the clock runs on
  };

  // Inputs:
  //   inputs         how many inputs (>= 1); each keeps its own newest stamp, since estimates lag
  //                  the readings by a clip's span and a model's queue, which is no restart
  //   max_future     [s] > 0
  //   restart_after  [s] > 0: the clock, or an input with no clock, going back further than this
  //                  restarts the display
  // Throws std::invalid_argument otherwise.
  DisplayClock(int inputs, double max_future, double restart_after);

  // Reads the clock, now_ns (0: not started). Returns true when it went back more than
  // restart_after since the last reading: the display restarts (forget what is shown).
  bool CheckClock(std::uint64_t now_ns);

  // Whether input `input`'s message stamped stamp_ns may be shown at clock now_ns; CheckClock(now_ns)
  // first. *restarted is set true when the display restarted: the clock went back, or (no clock
  // yet) this input did; the message is then the new pass's first. A shown stamp becomes the input's
  // newest if it is newer.
  Verdict Admit(int input, std::uint64_t stamp_ns, std::uint64_t now_ns, bool* restarted);

  // The display's now at clock now_ns: the clock (the plot scrolls and values age while inputs
  // pause) but never before the newest input (latency), and the newest input while the clock has
  // not started or is more than restart_after behind it (a replay restarting, until its first
  // message moves the newest stamp back). 0 when there is neither.
  std::uint64_t DisplayNow(std::uint64_t now_ns) const;

  // Input's newest shown stamp since the last restart (0: none).
  std::uint64_t Newest(int input) const { return newest_.at(input); }
  std::uint64_t Restarts() const { return restarts_; }

 private:
  std::uint64_t NewestOfAll() const;
  void Restart(double previous_end);

  double max_future_, restart_after_;
  std::vector<std::uint64_t> newest_;
  double last_clock_ = 0;  // [s] the clock when last read
  // [s] the previous pass's latest time: stamps ahead of the clock up to it are that pass's.
  double clock_before_restart_;
  std::uint64_t restarts_ = 0;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_DISPLAY_CLOCK_H_
