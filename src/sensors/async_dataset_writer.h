#ifndef CLOTHWIND_SENSORS_ASYNC_DATASET_WRITER_H_
#define CLOTHWIND_SENSORS_ASYNC_DATASET_WRITER_H_

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "sensors/dataset_writer.h"

namespace clothwind::sensors {

// Records clips on a thread of its own, so the camera callback that makes a clip never waits for
// the disk: a clip is 30 JPEGs and a label, each fsync'ed (DatasetWriter), which takes
// milliseconds on an SSD and can take seconds on an SD card or a USB stick. The queue is bounded;
// a clip that finds it full is not recorded and is counted (the frames keep flowing).
class AsyncDatasetWriter {
 public:
  struct Stats {
    uint64_t written = 0;          // clips recorded
    uint64_t failed = 0;           // clips DatasetWriter::Write refused (last_error says why)
    // Of the written, those recorded with a problem after (ClipRecordedWithAProblem: an index
    // rewrite, the replaced copy's removal, the folder's sync); last_problem says the last.
    uint64_t problems = 0;
    std::string last_problem;
    uint64_t dropped = 0;          // clips not queued: the queue was full
    uint64_t abandoned = 0;        // clips queued but not recorded: DrainBy's deadline came first
    size_t queued = 0;             // clips waiting now
    double last_write_s = 0.0;     // wall time the last write took [s]
    double max_write_s = 0.0;      // the longest write so far [s]
    std::string last_error;        // of the last failed write
    // Clips in place but not yet listed in index.json (the writer's index_interval); when the
    // last index rewrite failed, index_error says why (cleared by the next one that works).
    size_t unlisted = 0;
    std::string index_error;
  };

  // Inputs:
  //   writer     an opened DatasetWriter (owned from now on)
  //   max_queue  clips waiting at most (>= 1)
  AsyncDatasetWriter(std::unique_ptr<DatasetWriter> writer, size_t max_queue = 16);
  // Records what is queued, lists it in index.json, then stops the thread. While idle the
  // thread rewrites the index once clips have waited index_interval to be listed, so a
  // recording that pauses (a replay that ended) does not leave its last clips unlisted.
  ~AsyncDatasetWriter();
  AsyncDatasetWriter(const AsyncDatasetWriter&) = delete;
  AsyncDatasetWriter& operator=(const AsyncDatasetWriter&) = delete;

  // Queues one clip (its frames are shared, not copied: they must not be changed afterwards).
  // Returns false when the queue was full (counted in dropped). With `wait_for_room` it waits for
  // the thread to take a clip instead: for the last clips at shutdown, which a full queue of a
  // slow disk dropped without a word (no report came after them).
  bool Enqueue(LabelledClip clip, ClipSourceInfo source, bool wait_for_room = false);
  // The same, waiting for room until `room_deadline` at most (then counted in abandoned, as the
  // clips DrainBy gives up).
  bool Enqueue(LabelledClip clip, ClipSourceInfo source, std::chrono::steady_clock::time_point room_deadline);

  // Blocks until every queued clip is recorded (or failed) and index.json lists them (or its
  // rewrite failed: stats().index_error).
  void Drain();
  // Drain for a shutdown that may be cut short (roslaunch kills a node 17 s after Ctrl-C): the
  // index is rewritten before the next clip and after each one, so whatever is on disk when the
  // process dies is listed; clips still queued at `deadline` are not recorded.
  // Inputs:
  //   deadline   when to give up on the clips still queued
  // Outputs:
  //   abandoned  (appended) folder names of the clips given up, for the log; may be null
  // A clip is started only if it would land by the deadline, at the pace of the last write: one
  // started just before it ran past it (a slow card's 10 s clip past roslaunch's SIGKILL). Returns
  // true when every queued clip was recorded (or failed) and listed by the deadline. On false a
  // clip being written is still finished by the thread (and listed).
  // It is for a shutdown: once it has given up, the writer starts no clip again, and Enqueue
  // refuses (counted dropped) what comes after.
  bool DrainBy(std::chrono::steady_clock::time_point deadline, std::vector<std::string>* abandoned);

  // Asks the thread to rewrite index.json once the clips queued now are written (if any clip is
  // unlisted then); returns at once.
  void RequestIndexFlush();

  Stats stats() const;
  // DatasetWriter::FolderLost of the folder being written (any thread).
  std::string FolderLost() const { return writer_->FolderLost(); }
  const std::string& root() const { return root_; }
  size_t size_at_open() const { return size_at_open_; }
  size_t recovered() const { return recovered_; }

 private:
  void Run();
  bool HasRoom() const { return queue_.size() < max_queue_ || stop_; }  // (mutex held)
  // Queues the clip if there is room, else counts it in *refused; unlocks `lock` (held) when queued
  // and wakes the thread. Returns whether it was queued.
  bool Queue(LabelledClip clip, ClipSourceInfo source, std::unique_lock<std::mutex>* lock, uint64_t* refused);

  std::unique_ptr<DatasetWriter> writer_;  // used by the thread only, after construction
  const size_t max_queue_;
  const std::string root_;
  const size_t size_at_open_, recovered_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_, room_;
  std::deque<std::pair<LabelledClip, ClipSourceInfo>> queue_;
  bool busy_ = false, stop_ = false, flush_requested_ = false, flushing_ = false;
  bool list_each_clip_ = false;  // DrainBy: rewrite the index before the next clip and after each
  bool flush_first_ = false;     // DrainBy: rewrite it before the next clip
  // DrainBy: no clip is started that would land after this (at the last write's pace)
  std::optional<std::chrono::steady_clock::time_point> start_by_;
  bool gave_up_ = false;  // the thread starts no more clips (start_by_ too near); DrainBy names them
  // Rewrites the index now if clips are unlisted (thread only, mutex not held); updates stats_.
  void FlushIndex(std::unique_lock<std::mutex>* lock);
  Stats stats_;
  std::thread thread_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_ASYNC_DATASET_WRITER_H_
