#include "sensors/async_dataset_writer.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace clothwind::sensors {

AsyncDatasetWriter::AsyncDatasetWriter(std::unique_ptr<DatasetWriter> writer, size_t max_queue)
    : writer_(std::move(writer)),
      max_queue_(max_queue),
      root_(writer_ ? writer_->root() : std::string()),
      size_at_open_(writer_ ? writer_->size() : 0),
      recovered_(writer_ ? writer_->recovered() : 0) {
  if (!writer_) throw std::invalid_argument("AsyncDatasetWriter: no writer");
  if (max_queue < 1) throw std::invalid_argument("AsyncDatasetWriter: max_queue must be >= 1");
  thread_ = std::thread(&AsyncDatasetWriter::Run, this);
}

AsyncDatasetWriter::~AsyncDatasetWriter() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  room_.notify_all();
  thread_.join();
}

bool AsyncDatasetWriter::Enqueue(LabelledClip clip, ClipSourceInfo source, bool wait_for_room) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (wait_for_room) room_.wait(lock, [this] { return HasRoom(); });
  return Queue(std::move(clip), std::move(source), &lock, &stats_.dropped);
}

bool AsyncDatasetWriter::Enqueue(LabelledClip clip, ClipSourceInfo source,
                                 std::chrono::steady_clock::time_point room_deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  room_.wait_until(lock, room_deadline, [this] { return HasRoom(); });
  // Given up at the deadline (a shutdown's), not dropped by a full queue.
  return Queue(std::move(clip), std::move(source), &lock, &stats_.abandoned);
}

bool AsyncDatasetWriter::Queue(LabelledClip clip, ClipSourceInfo source, std::unique_lock<std::mutex>* lock,
                               uint64_t* refused) {
  // After DrainBy gave up (the shutdown's deadline) nothing more is written: refused and counted,
  // where it would have waited in the queue unwritten and uncounted.
  if (queue_.size() >= max_queue_ || gave_up_) {
    ++*refused;
    return false;
  }
  queue_.emplace_back(std::move(clip), std::move(source));
  lock->unlock();
  wake_.notify_one();
  return true;
}

void AsyncDatasetWriter::Drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  flush_requested_ = true;
  wake_.notify_one();
  // (queue_ holds nothing once DrainBy gave up: it names and clears what it gives up.)
  idle_.wait(lock, [this] { return (queue_.empty() || gave_up_) && !busy_ && !flush_requested_ && !flushing_; });
}

bool AsyncDatasetWriter::DrainBy(std::chrono::steady_clock::time_point deadline,
                                 std::vector<std::string>* abandoned) {
  std::unique_lock<std::mutex> lock(mutex_);
  list_each_clip_ = true;
  flush_first_ = true;
  flush_requested_ = true;
  wake_.notify_one();
  start_by_ = deadline;
  auto done = [this] {
    return (queue_.empty() || gave_up_) && !busy_ && !flush_requested_ && !flush_first_ && !flushing_;
  };
  if (idle_.wait_until(lock, deadline, done) && queue_.empty()) return true;
  for (const auto& item : queue_) {
    ++stats_.abandoned;
    if (abandoned)
      abandoned->push_back(item.first.clip.frames.empty() ? "(a clip with no frames)"
                                                          : ClipFolderName(item.first.clip.frames.front().stamp));
  }
  queue_.clear();
  gave_up_ = true;  // (also at the deadline itself): nothing more is started or queued
  room_.notify_all();
  return false;
}

void AsyncDatasetWriter::RequestIndexFlush() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    flush_requested_ = true;
  }
  wake_.notify_one();
}

AsyncDatasetWriter::Stats AsyncDatasetWriter::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  Stats s = stats_;
  s.queued = queue_.size() + (busy_ ? 1 : 0);
  return s;
}

void AsyncDatasetWriter::FlushIndex(std::unique_lock<std::mutex>* lock) {
  flushing_ = true;  // (not busy_: no clip is being written, and stats().queued counts busy_)
  lock->unlock();
  std::string error;
  try {
    writer_->FlushIndex();
  } catch (const std::exception& e) {
    error = e.what();
  }
  const size_t unlisted = writer_->unlisted();
  lock->lock();
  flushing_ = false;
  stats_.unlisted = unlisted;
  stats_.index_error = error;
}

void AsyncDatasetWriter::Run() {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto interval = std::chrono::duration<double>(writer_->index_interval());
  auto has_work = [this] { return stop_ || flush_requested_ || flush_first_ || (!queue_.empty() && !gave_up_); };
  for (;;) {
    // Clips waiting to be listed: wake after the interval even if nothing else comes.
    if (stats_.unlisted > 0 && interval.count() > 0) {
      if (!wake_.wait_for(lock, interval, has_work)) {
        FlushIndex(&lock);
        continue;
      }
    } else {
      wake_.wait(lock, has_work);
    }
    if (flush_first_) {  // DrainBy: what is on disk listed before the next clip
      flush_first_ = false;
      FlushIndex(&lock);
      idle_.notify_all();
      continue;
    }
    if (!queue_.empty() && !gave_up_ && start_by_ &&
        std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                std::chrono::duration<double>(stats_.last_write_s)) >
            *start_by_) {
      gave_up_ = true;  // the next clip would land after DrainBy's deadline: it names them instead
    }
    if (queue_.empty() || gave_up_) {  // stop_ or a flush asked for, and nothing left to write
      // Cleared before the rewrite, so a request made while it runs (FlushIndex unlocks) is
      // served by another one: cleared after, it was lost, and Drain returned with a clip
      // written during the rewrite unlisted.
      flush_requested_ = false;
      FlushIndex(&lock);
      idle_.notify_all();
      if (stop_) break;
      continue;
    }
    auto item = std::move(queue_.front());
    queue_.pop_front();
    busy_ = true;
    lock.unlock();
    room_.notify_all();
    const auto start = std::chrono::steady_clock::now();
    std::string error, problem;
    try {
      writer_->Write(item.first, item.second);
    } catch (const ClipRecordedWithAProblem& e) {
      problem = e.what();  // recorded: counted written, the problem said
    } catch (const std::exception& e) {
      error = e.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const size_t unlisted = writer_->unlisted();
    lock.lock();
    busy_ = false;
    stats_.unlisted = unlisted;
    stats_.last_write_s = seconds;
    stats_.max_write_s = std::max(stats_.max_write_s, seconds);
    if (error.empty()) {
      ++stats_.written;
      if (!problem.empty()) {
        ++stats_.problems;
        stats_.last_problem = problem;
      }
      if (list_each_clip_) FlushIndex(&lock);
    } else {
      ++stats_.failed;
      stats_.last_error = error;
    }
    if (queue_.empty()) idle_.notify_all();
  }
  idle_.notify_all();
}

}  // namespace clothwind::sensors
