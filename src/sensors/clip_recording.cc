#include "sensors/clip_recording.h"

#include <filesystem>
#include <stdexcept>
#include <utility>

#include "common/formatted.h"

namespace clothwind::sensors {

ClipRecording::ClipRecording(Options options, LogFn log, double now)
    : options_(std::move(options)), log_(std::move(log)) {
  if (!options_.is_mount_point) options_.is_mount_point = [](const std::string& dir) { return IsMountPoint(dir); };
  if (!log_) log_ = [](LogLevel, const std::string&) {};
  TryOpen(now);
}

ClipRecording::~ClipRecording() {
  if (closer_.joinable()) closer_.join();
}

void ClipRecording::TryOpen(double now) {
  if (!enabled() || writer_) return;
  last_open_attempt_ = now;
  try {
    writer_ = std::make_unique<AsyncDatasetWriter>(
        std::make_unique<DatasetWriter>(options_.dir, options_.jpeg_quality, options_.index_interval), options_.queue);
    if (!error_.empty()) log_(LogLevel::kInfo, "recording works again");
    error_.clear();
    mounted_ = options_.is_mount_point(options_.dir);
    log_(LogLevel::kInfo,
         Formatted("recording clips to %s (%zu already there%s)", options_.dir.c_str(), writer_->size_at_open(),
                   writer_->recovered() > 0
                       ? (", " + std::to_string(writer_->recovered()) + " leftovers of an earlier run cleared").c_str()
                       : ""));
  } catch (const std::exception& e) {
    if (error_ != e.what())
      log_(LogLevel::kError, Formatted("not recording (publishing clips still; retrying every %.0f s): %s",
                                       options_.reopen_every, e.what()));
    error_ = e.what();
  }
}

void ClipRecording::Record(const LabelledClip& clip, const ClipSourceInfo& source) {
  if (!enabled()) return;
  if (!writer_) {
    ++not_recorded_;
    return;
  }
  writer_->Enqueue(clip, source);
}

std::vector<std::string> ClipRecording::Poll(double now, bool input_idle) {
  std::vector<std::string> problems;
  if (writer_) {
    if (const std::string lost = writer_->FolderLost(); !lost.empty()) {
      problems.push_back(lost + "; reopening it every " + std::to_string(static_cast<int>(options_.reopen_every)) +
                         " s once it is there");
      // Its tally kept, its queued clips (the one being written among them) counted as not
      // recorded: they are written into a folder that is gone, or is another, and fail.
      const auto r = writer_->stats();
      written_before_ += r.written;
      failed_before_ += r.failed;
      dropped_before_ += r.dropped;
      lost_queued_ += r.queued;
      failed_seen_ = dropped_seen_ = problems_seen_ = 0;
      index_error_seen_.clear();
      if (closer_.joinable()) closer_.join();  // done: no reopen before it closed (below)
      closer_closed_ = false;
      closer_ = std::thread([this, lost_writer = std::move(writer_)]() mutable {
        lost_writer.reset();
        closer_closed_ = true;
      });
      folder_lost_ = true;
      error_ = lost;
      last_open_attempt_ = now;
    }
  }
  if (!writer_ && enabled() && now - last_open_attempt_ >= options_.reopen_every) {
    std::error_code ec;
    if (!closer_closed_) {
      // The lost writer still finishing its clip: two writers in one path would each rewrite the
      // index from their own list.
      last_open_attempt_ = now;
    } else if (folder_lost_ && !std::filesystem::is_directory(options_.dir, ec)) {
      last_open_attempt_ = now;
      error_ = "the recording folder " + options_.dir + " is gone; waiting for it to come back";
    } else if (folder_lost_ && mounted_ && !options_.is_mount_point(options_.dir)) {
      // A disk was mounted there: its bare mount point (an fstab entry) is not the disk.
      last_open_attempt_ = now;
      error_ = "the disk mounted at " + options_.dir + " is not there; waiting for it to come back";
    } else {
      TryOpen(now);
    }
  }
  if (writer_ && !index_flush_asked_ && input_idle) {
    writer_->RequestIndexFlush();
    index_flush_asked_ = true;
  }
  if (writer_) {  // the recording thread's failures
    const auto r = writer_->stats();
    if (r.failed > failed_seen_) problems.push_back("recording failed: " + r.last_error);
    if (r.dropped > dropped_seen_)
      problems.push_back("recording too slow: " + std::to_string(r.dropped - dropped_seen_) +
                         " clip(s) not recorded (queue of " + std::to_string(options_.queue) + " full)");
    if (r.problems > problems_seen_) problems.push_back(r.last_problem);
    failed_seen_ = r.failed;
    dropped_seen_ = r.dropped;
    problems_seen_ = r.problems;
    if (!r.index_error.empty() && r.index_error != index_error_seen_)
      problems.push_back("index.json not rewritten (the clips are in place; the next rewrite or the next opening of "
                         "the folder lists them): " + r.index_error);
    index_error_seen_ = r.index_error;
  }
  return problems;
}

ClipRecording::Tally ClipRecording::tally() const {
  const auto r = writer_ ? writer_->stats() : AsyncDatasetWriter::Stats();
  Tally t;
  t.recorded = written_before_ + r.written;
  t.not_recorded = not_recorded_ + lost_queued_ + failed_before_ + dropped_before_ + r.failed + r.dropped;
  t.waiting = r.queued;
  t.unlisted = r.unlisted;
  t.max_write_s = r.max_write_s;
  return t;
}

std::vector<std::string> ClipRecording::Finish(const std::vector<LabelledClip>& waiting, const ClipSourceInfo& source,
                                               std::chrono::steady_clock::time_point deadline) {
  // (A lost folder's writer still closing is joined by the destructor, after the last clips: a
  // yanked disk's write can hang past roslaunch's SIGKILL.)
  const double budget = std::chrono::duration<double>(deadline - std::chrono::steady_clock::now()).count();
  std::vector<std::string> abandoned;
  if (!enabled()) return abandoned;
  if (writer_ && (!waiting.empty() || writer_->stats().queued > 0))
    log_(LogLevel::kInfo, Formatted("recording the last %zu clips into %s (at most %.0f s)",
                                    waiting.size() + writer_->stats().queued, writer_->root().c_str(), budget));
  for (const auto& c : waiting) {
    if (!writer_) {
      ++not_recorded_;
    } else if (!writer_->Enqueue(c, source, deadline) && !c.clip.frames.empty()) {
      abandoned.push_back(ClipFolderName(c.clip.frames.front().stamp));
    }
  }
  if (!writer_) {
    if (not_recorded_ > 0)
      log_(LogLevel::kWarn, Formatted("%llu clips not recorded (no recording folder open: %s)",
                                      static_cast<unsigned long long>(not_recorded_), error_.c_str()));
    if (written_before_ + failed_before_ + dropped_before_ + lost_queued_ > 0)
      log_(LogLevel::kInfo,
           Formatted("recording into %s ends with its folder lost: %llu clips written, %llu failed, %llu dropped "
                     "(queue full), %llu queued when a folder was lost, before",
                     options_.dir.c_str(), static_cast<unsigned long long>(written_before_),
                     static_cast<unsigned long long>(failed_before_), static_cast<unsigned long long>(dropped_before_),
                     static_cast<unsigned long long>(lost_queued_)));
    return abandoned;
  }
  writer_->DrainBy(deadline, &abandoned);
  const auto s = writer_->stats();
  if (!abandoned.empty())
    log_(LogLevel::kError, Formatted("%zu clips not recorded: the disk did not write them within %.0f s of shutdown "
                                     "(roslaunch kills a node 17 s after Ctrl-C): %s",
                                     abandoned.size(), budget, JoinNames(abandoned).c_str()));
  if (s.failed > 0) log_(LogLevel::kError, "last failed clip write: " + s.last_error);
  if (s.problems > 0)
    log_(LogLevel::kWarn, Formatted("%llu clips recorded with a problem after; the last: %s",
                                    static_cast<unsigned long long>(s.problems), s.last_problem.c_str()));
  if (!s.index_error.empty()) log_(LogLevel::kError, "index.json not rewritten: " + s.index_error);
  log_(LogLevel::kInfo,
       Formatted("recording into %s ends: %llu clips written, %llu failed, %llu dropped (queue full), %zu given up "
                 "at shutdown, %llu not recorded (no folder open), %llu queued when a folder was lost",
                 writer_->root().c_str(), static_cast<unsigned long long>(written_before_ + s.written),
                 static_cast<unsigned long long>(failed_before_ + s.failed),
                 static_cast<unsigned long long>(dropped_before_ + s.dropped), abandoned.size(),
                 static_cast<unsigned long long>(not_recorded_), static_cast<unsigned long long>(lost_queued_)));
  return abandoned;
}

std::string ClipRecording::JoinNames(const std::vector<std::string>& names) {
  std::string out;
  const size_t shown = names.size() <= 6 ? names.size() : 4;
  for (size_t i = 0; i < shown; ++i) out += (i ? ", " : "") + names[i];
  if (shown < names.size()) out += ", ... (" + std::to_string(names.size() - shown - 1) + " more), " + names.back();
  return out;
}

}  // namespace clothwind::sensors
