// Watches the session bags `rosbag record -o <prefix>` writes (field.launch bag:=true) and the
// disk they go to, for diagnostics: rosbag record publishes none, so a recorder that died (a bag
// write error, the disk full) or a disk about to fill showed nowhere while every other node said OK.
// rosbag names a bag <prefix>_<YYYY-MM-DD-HH-MM-SS>.bag.active while it writes it and renames it to
// .bag when it closes it; a recorder that is killed leaves the .active name (the bag then needs
// `rosbag reindex`).
#ifndef CLOTHWIND_SENSORS_SESSION_BAG_WATCH_H_
#define CLOTHWIND_SENSORS_SESSION_BAG_WATCH_H_

#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace clothwind {
namespace sensors {

// Free and total bytes of the filesystem a folder is on.
struct DiskSpace {
  uint64_t available = 0;  // [B] free to an unprivileged writer
  uint64_t capacity = 0;   // [B]
};

// statvfs(3) of `folder`.
// Outputs: space (on success), error (why not, naming the folder).
// Returns true on success.
bool StatDiskSpace(const std::string& folder, DiskSpace* space, std::string* error);

// What the watch found at one poll.
struct SessionBagReport {
  enum class Level { kOk, kWarn, kError };
  Level level = Level::kOk;
  std::string message;        // one line; every WARN that holds, joined by "; "
  std::string bag;            // the bag being written (its .active path), "" when none
  uint64_t bag_bytes = 0;     // [B] its size
  double write_rate = 0;      // [B/s] its growth over the last `rate_window` seconds
  double seconds_since_growth = 0;  // [s] since its size last changed
  uint64_t available = 0;     // [B] free on the bags' disk (0 when unknown)
  double seconds_to_full = std::numeric_limits<double>::infinity();  // at write_rate
  int bags_started = 0;       // bags of this prefix begun since the watch started (a restart adds one)
  int bags_closed = 0;        // bags of this prefix closed (renamed to .bag) since then
  std::vector<std::string> left_open;  // .active bags begun since then that stopped while a newer one is written
};

// Polls the folder of a bag prefix. Not thread-safe; call Poll from one thread.
class SessionBagWatch {
 public:
  struct Options {
    std::string prefix;             // rosbag record's -o: <folder>/<name>
    double stall_after = 10;        // [s] a bag not growing for longer is an ERROR
    double start_grace = 15;        // [s] from the first poll, for the recorder to open its first bag;
                                    // a bag last written longer before the first poll is not this session's
    double rate_window = 10;        // [s] over which the write rate is measured
    uint64_t min_available = 2000000000;  // [B] less free space is a WARN
    double min_seconds_to_full = 600;     // [s] a disk full sooner at the write rate is a WARN
  };

  // Inputs:
  //   options     as above; prefix as rosbag record's -o takes it: "/data/session" (bags
  //               /data/session_<date>.bag), "/data/session.bag" (the same) or "/data/" (/data/_<date>.bag)
  //   disk_space  how the free space is read (StatDiskSpace; tests pass their own)
  // Throws std::invalid_argument naming the option that is out of range.
  explicit SessionBagWatch(Options options,
                           std::function<bool(const std::string&, DiskSpace*, std::string*)> disk_space = StatDiskSpace);

  // Lists the prefix's bags and reads the disk.
  // Inputs: now  [s] a monotonic clock
  // Returns what was found; ERROR when no bag is being written past the start grace, or the newest
  // has not grown for `stall_after` s, or the folder cannot be read; WARN for little free space, a
  // bag left open by a recorder that stopped, or a recorder that restarted.
  SessionBagReport Poll(double now);

  const std::string& folder() const { return folder_; }

 private:
  Options options_;
  std::function<bool(const std::string&, DiskSpace*, std::string*)> disk_space_;
  std::string folder_, name_;  // the prefix split: <folder_>/<name_>_<date>.bag[.active]
  bool started_ = false;
  double start_ = 0;
  std::set<std::string> before_;  // bags last written start_grace before the first poll: not this session's
  std::map<std::string, std::pair<uint64_t, double>> sizes_;  // .active path -> (size, when it last changed)
  std::set<std::string> begun_, closed_;
  std::string current_;
  std::deque<std::pair<double, uint64_t>> samples_;  // (now, size) of current_ over rate_window
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_SESSION_BAG_WATCH_H_
