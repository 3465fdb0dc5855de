// The recording folder of a clip stream, as clip_buffer_node keeps it: opened at start and, after
// it failed to open or was lost (a USB disk unplugged, or replugged and mounted again), reopened
// every `reopen_every` seconds once it is back; clips queued to its writer (AsyncDatasetWriter, a
// thread of its own); the writer's failures turned into messages, each once; the tallies kept
// across reopenings; the last clips recorded at shutdown within a budget. ROS-free and not
// thread-safe: the node calls it under its own mutex.
#ifndef CLOTHWIND_SENSORS_CLIP_RECORDING_H_
#define CLOTHWIND_SENSORS_CLIP_RECORDING_H_

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "sensors/async_dataset_writer.h"
#include "sensors/frame_source.h"

namespace clothwind::sensors {

class ClipRecording {
 public:
  struct Options {
    std::string dir;             // the dataset folder; "" = not recording
    int jpeg_quality = 95;       // 1..100
    double index_interval = 30;  // [s] DatasetWriter's
    size_t queue = 16;           // clips waiting for the disk at most (16 x 30 x 300^2 B = 43 MB of mono8)
    double reopen_every = 10;    // [s] between attempts to open a folder that failed or was lost
    // Whether a folder is a mount point (IsMountPoint); tests pass their own.
    std::function<bool(const std::string&)> is_mount_point;
  };
  // Opens the folder (when set) at time now [s, monotonic]; a failure is kept in error() and
  // logged, and the folder is tried again by Poll.
  // log: where what happens is said (the node's ROS log).
  ClipRecording(Options options, LogFn log, double now);
  // Joins the thread closing a lost folder's writer; then the open writer records what it holds.
  ~ClipRecording();
  ClipRecording(const ClipRecording&) = delete;
  ClipRecording& operator=(const ClipRecording&) = delete;

  bool enabled() const { return !options_.dir.empty(); }
  bool open() const { return writer_ != nullptr; }
  const std::string& dir() const { return options_.dir; }
  // Why the folder is not open ("" when it is, or when not recording).
  const std::string& error() const { return error_; }

  // Queues a clip; counted as not recorded when no folder is open, and by the writer when its
  // queue is full.
  void Record(const LabelledClip& clip, const ClipSourceInfo& source);

  // Every tick, at time now [s, monotonic]. A lost folder's writer is closed off the caller's
  // thread (closing waits for the clip being written: seconds on a slow card, which held the
  // camera callbacks) and the folder reopened once it is a folder again, and, if it was a mount
  // point, a mount point again (a bare mount point is not the disk): never created again, so clips
  // never land on a bare mount point. input_idle: input has stopped (a replay ended), so the clips
  // recorded since the last index rewrite are listed now, once per stop. Returns what newly went
  // wrong: the folder lost (once), writes that failed since the last call (with the last one's
  // error), clips recorded with a problem after (the last one's), clips the full queue dropped
  // since then, an index rewrite's error (once per error).
  std::vector<std::string> Poll(double now, bool input_idle);
  // Input came again: the next stop lists the index again.
  void InputArrived() { index_flush_asked_ = false; }

  struct Tally {
    uint64_t recorded = 0;      // clips written, over every folder opened
    // Failed, dropped (queue full), queued in a folder when it was lost, or with no folder open;
    // not those given up at shutdown (Finish names them).
    uint64_t not_recorded = 0;
    size_t waiting = 0;         // queued for the disk now
    size_t unlisted = 0;        // written, not yet in index.json
    double max_write_s = 0;     // the slowest clip write of the open writer [s]
  };
  Tally tally() const;

  // At shutdown: records `waiting` (clips labelled now, with `source`), waiting for room in the
  // queue, then for the queue to be written, until `deadline` at most (taken before the waiting
  // clips were labelled: the budget is the whole shutdown's); logs what was given up (named) and
  // the tally. Returns the names of the clips given up.
  std::vector<std::string> Finish(const std::vector<LabelledClip>& waiting, const ClipSourceInfo& source,
                                  std::chrono::steady_clock::time_point deadline);

  // "a, b, c" or "a, b, ... (n more), z": a log line stays readable with hundreds of clips.
  static std::string JoinNames(const std::vector<std::string>& names);

 private:
  void TryOpen(double now);

  Options options_;
  LogFn log_;
  std::unique_ptr<AsyncDatasetWriter> writer_;
  std::string error_;                   // why the folder is not open
  bool folder_lost_ = false;            // it was open and went: reopened only once it exists again
  bool mounted_ = false;                // the folder was a mount point when it was opened
  double last_open_attempt_ = 0;        // [s]
  std::thread closer_;                  // closes a lost folder's writer
  std::atomic<bool> closer_closed_{true};  // it has (no writer closing now)
  uint64_t written_before_ = 0, failed_before_ = 0, dropped_before_ = 0;  // lost writers' tallies
  uint64_t not_recorded_ = 0;           // clips with no folder open
  uint64_t lost_queued_ = 0;            // clips queued (or being written) when their folder was lost
  uint64_t failed_seen_ = 0, dropped_seen_ = 0, problems_seen_ = 0;  // the open writer's, as last reported
  std::string index_error_seen_;
  bool index_flush_asked_ = false;      // since input last came
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CLIP_RECORDING_H_
