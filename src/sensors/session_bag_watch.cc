#include "sensors/session_bag_watch.h"

#include <sys/statvfs.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <regex>
#include <stdexcept>
#include <system_error>

#include "common/formatted.h"

namespace clothwind {
namespace sensors {
namespace fs = std::filesystem;

bool StatDiskSpace(const std::string& folder, DiskSpace* space, std::string* error) {
  struct statvfs s;
  if (::statvfs(folder.c_str(), &s) != 0) {
    *error = "cannot read the free space of " + folder + ": " + std::strerror(errno);
    return false;
  }
  space->available = static_cast<uint64_t>(s.f_bavail) * s.f_frsize;
  space->capacity = static_cast<uint64_t>(s.f_blocks) * s.f_frsize;
  return true;
}

namespace {

constexpr const char* kActive = ".bag.active";
constexpr const char* kClosed = ".bag";

bool EndsWith(const std::string& s, const std::string& end) {
  return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
}

// Whether `rest`, a file name after "<name>_", is rosbag record's "YYYY-MM-DD-HH-MM-SS[_N].bag" or
// ".bag.active": another recorder's "<name>_cam2_<date>.bag" is not this one's.
bool IsBagDateName(const std::string& rest) {
  static const std::regex kDate(R"(\d{4}-\d{2}-\d{2}-\d{2}-\d{2}-\d{2}(_\d+)?\.bag(\.active)?)");
  return std::regex_match(rest, kDate);
}

std::string Megabytes(double bytes) { return Formatted("%.1f MB", bytes / 1e6); }

std::string Duration(double seconds) {
  if (seconds < 120) return Formatted("%.0f s", seconds);
  if (seconds < 7200) return Formatted("%.0f min", seconds / 60);
  return Formatted("%.1f h", seconds / 3600);
}

}  // namespace

SessionBagWatch::SessionBagWatch(Options options,
                                 std::function<bool(const std::string&, DiskSpace*, std::string*)> disk_space)
    : options_(std::move(options)), disk_space_(std::move(disk_space)) {
  if (options_.prefix.empty())
    throw std::invalid_argument("the bag prefix must be rosbag record's -o (<folder>/<name>), got nothing");
  const fs::path prefix(options_.prefix);
  folder_ = prefix.parent_path().empty() ? "." : prefix.parent_path().string();
  // As rosbag: a ".bag" ending is dropped before "_<date>" is added, and "<folder>/" names
  // "<folder>/_<date>.bag".
  std::string name = prefix.filename().string();
  if (EndsWith(name, ".bag")) name.resize(name.size() - 4);
  name_ = name + "_";
  if (!(options_.stall_after > 0) || !std::isfinite(options_.stall_after))
    throw std::invalid_argument("stall_after must be a finite number of seconds > 0");
  if (!(options_.start_grace >= 0) || !std::isfinite(options_.start_grace))
    throw std::invalid_argument("start_grace must be a finite number of seconds >= 0");
  if (!(options_.rate_window > 0) || !std::isfinite(options_.rate_window))
    throw std::invalid_argument("rate_window must be a finite number of seconds > 0");
  if (!(options_.min_seconds_to_full >= 0) || !std::isfinite(options_.min_seconds_to_full))
    throw std::invalid_argument("min_seconds_to_full must be a finite number of seconds >= 0 (0: no warning)");
}

SessionBagReport SessionBagWatch::Poll(double now) {
  SessionBagReport r;
  using Level = SessionBagReport::Level;
  std::vector<std::string> warnings;

  // The prefix's bags now: .active ones with their size and modification time.
  std::error_code ec;
  std::map<std::string, std::pair<uint64_t, fs::file_time_type>> active;
  std::set<std::string> closed;
  for (fs::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string file = it->path().filename().string();
    if (file.compare(0, name_.size(), name_) != 0 || !IsBagDateName(file.substr(name_.size()))) continue;
    std::error_code file_ec;
    if (EndsWith(file, kActive)) {
      const uint64_t size = it->file_size(file_ec);
      const fs::file_time_type written = it->last_write_time(file_ec);
      if (!file_ec) active[it->path().string()] = {size, written};  // gone meanwhile: closed
    } else if (EndsWith(file, kClosed)) {
      closed.insert(it->path().string());
    }
  }
  if (ec) {
    r.level = Level::kError;
    r.message = "cannot read the bag folder " + folder_ + ": " + ec.message();
    return r;
  }
  if (!started_) {
    // Bags last written before the start grace are an earlier session's; a recorder launched
    // with this watch may have opened its bag a moment before the first poll.
    started_ = true;
    start_ = now;
    // Either way: a bag dated ahead (the clock stepped back since) is no more this session's.
    const fs::file_time_type wall = fs::file_time_type::clock::now();
    const auto grace = std::chrono::duration_cast<fs::file_time_type::duration>(
        std::chrono::duration<double>(options_.start_grace));
    const auto old = [&](fs::file_time_type t) { return t < wall - grace || t > wall + grace; };
    for (const auto& a : active)
      if (old(a.second.second)) before_.insert(a.first);
    for (const std::string& path : closed) {
      std::error_code time_ec;
      const fs::file_time_type written = fs::last_write_time(path, time_ec);
      if (time_ec || old(written)) before_.insert(path);
    }
  }

  // The bag being written: of this session's, the one that grew last on the monotonic clock (the
  // last modified first, for bags not yet seen to grow). A bag from before the session is never
  // it: a leftover, or one dated ahead by a clock stepped back, passed for the live one.
  std::string current;
  double grew = -std::numeric_limits<double>::infinity();
  fs::file_time_type newest = fs::file_time_type::min();
  for (const auto& [path, a] : active) {
    const auto seen = sizes_.find(path);
    if (seen == sizes_.end() || seen->second.first != a.first) sizes_[path] = {a.first, now};  // new or grown
    if (before_.count(path)) continue;
    begun_.insert(path);
    const double when = sizes_[path].second;
    if (current.empty() || when > grew || (when == grew && a.second > newest)) {
      current = path;
      grew = when;
      newest = a.second;
    }
  }
  for (const std::string& path : closed)
    if (!before_.count(path)) closed_.insert(path);
  if (current != current_) samples_.clear();
  current_ = current;

  r.bags_started = static_cast<int>(begun_.size());
  r.bags_closed = static_cast<int>(closed_.size());
  for (const auto& [path, a] : active) {
    if (path == current || !begun_.count(path)) continue;
    if (now - sizes_[path].second > options_.stall_after) r.left_open.push_back(path);
  }
  if (!r.left_open.empty())
    warnings.push_back("a recorder stopped without closing " + r.left_open.back() +
                       " (rosbag reindex it, then rename it to .bag)" +
                       (r.left_open.size() > 1 ? " and " + std::to_string(r.left_open.size() - 1) + " more" : ""));

  // The disk.
  DiskSpace space;
  std::string disk_error;
  const bool have_space = disk_space_(folder_, &space, &disk_error);
  if (have_space) {
    r.available = space.available;
  } else {
    warnings.push_back(disk_error);
  }

  if (!current.empty()) {
    r.bag = current;
    r.bag_bytes = active[current].first;
    r.seconds_since_growth = now - sizes_[current].second;
    samples_.emplace_back(now, r.bag_bytes);
    while (samples_.size() > 2 && now - samples_[1].first >= options_.rate_window) samples_.pop_front();
    const double span = samples_.back().first - samples_.front().first;
    if (span > 0 && samples_.back().second >= samples_.front().second)
      r.write_rate = static_cast<double>(samples_.back().second - samples_.front().second) / span;
  }
  if (have_space && r.write_rate > 0) r.seconds_to_full = static_cast<double>(space.available) / r.write_rate;
  if (have_space && space.available < options_.min_available)
    warnings.push_back(Megabytes(static_cast<double>(space.available)) + " free on " + folder_);
  else if (r.seconds_to_full < options_.min_seconds_to_full)
    warnings.push_back(folder_ + " is full in " + Duration(r.seconds_to_full) + " at " +
                       Megabytes(r.write_rate) + "/s");

  std::string warned;
  for (const std::string& w : warnings) warned += (warned.empty() ? "" : "; ") + w;
  if (current.empty()) {
    const double waited = now - start_;
    if (waited > options_.start_grace) {
      r.level = Level::kError;
      r.message = "no session bag " + (fs::path(folder_) / name_).string() + "*" + kActive + " is being written (for " +
                  Duration(waited) + "; is the recorder running?)";
    } else {
      r.level = warnings.empty() ? Level::kOk : Level::kWarn;
      r.message = "waiting for the recorder's first bag";
    }
  } else if (r.seconds_since_growth > options_.stall_after) {
    r.level = Level::kError;
    r.message = "the session bag " + current + " has not grown for " + Duration(r.seconds_since_growth) +
                " (the recorder stopped, or nothing comes to record)";
  } else {
    r.level = warnings.empty() ? Level::kOk : Level::kWarn;
    r.message = "recording " + fs::path(current).filename().string() + " at " + Megabytes(r.write_rate) + "/s";
  }
  if (!warned.empty()) r.message += "; " + warned;
  return r;
}

}  // namespace sensors
}  // namespace clothwind
