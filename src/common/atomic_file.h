// Writing files so that a crash or a power cut leaves the old version or the new one, never a
// half-written or empty file: every capability that records something (clips, datasets,
// trajectories, models, checkpoints, reports) writes through these.
#ifndef CLOTHWIND_COMMON_ATOMIC_FILE_H_
#define CLOTHWIND_COMMON_ATOMIC_FILE_H_

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace clothwind {

// Writes `size` bytes to `path` (created or truncated) and fsyncs them. On failure removes the
// file and throws std::runtime_error naming it and why (e.g. "No space left on device").
inline void WriteFileDurably(const std::string& path, const void* data, size_t size) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + path + " for writing: " + std::strerror(errno));
  const char* p = static_cast<const char*>(data);
  size_t left = size;
  std::string error;
  while (left > 0 && error.empty()) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = "cannot write " + path + ": " + std::strerror(n < 0 ? errno : EIO);
    } else {
      p += n;
      left -= static_cast<size_t>(n);
    }
  }
  // fsync before the rename that publishes it: otherwise a power cut can leave the new name
  // pointing at an empty file (ext4, xfs).
  if (error.empty() && ::fsync(fd) != 0) error = "cannot sync " + path + ": " + std::strerror(errno);
  if (::close(fd) != 0 && error.empty()) error = "cannot close " + path + ": " + std::strerror(errno);
  if (!error.empty()) {
    ::unlink(path.c_str());
    throw std::runtime_error(error);
  }
}

// fsyncs a file written by other means (a library's own writer), before it is renamed into place.
// Throws std::runtime_error naming it when that fails.
inline void SyncFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open " + path + " to sync it: " + std::strerror(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw std::runtime_error("cannot sync " + path + ": " + std::strerror(err));
}

// fsyncs a folder, so the renames and new names in it survive a power cut.
// Throws std::runtime_error naming it when that fails.
inline void SyncDirectory(const std::string& dir) {
  const int fd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open folder " + dir + ": " + std::strerror(errno));
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) throw std::runtime_error("cannot sync folder " + dir + ": " + std::strerror(err));
}

namespace atomic_file_internal {

// The first 8 hex digits of this boot's id (/proc/sys/kernel/random/boot_id), "" if unreadable.
inline std::string BootTag() {
  std::FILE* f = std::fopen("/proc/sys/kernel/random/boot_id", "r");
  if (!f) return "";
  char buf[64] = {0};
  const bool ok = std::fgets(buf, sizeof buf, f) != nullptr;
  std::fclose(f);
  std::string tag;
  for (const char* c = buf; ok && *c && tag.size() < 8; ++c)
    if (std::isxdigit(static_cast<unsigned char>(*c))) tag += *c;
  return tag.size() == 8 ? tag : "";
}

// When process `pid` started, in clock ticks after boot (/proc/<pid>/stat field 22), "" if
// unreadable (no such process).
inline std::string ProcessStartTicks(long pid) {
  std::FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
  if (!f) return "";
  char buf[1024] = {0};
  const size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  const std::string stat(buf, n);
  // Fields after the command name, which is in parentheses and may hold spaces or ')'.
  const size_t close = stat.rfind(')');
  if (close == std::string::npos) return "";
  size_t pos = close + 1;
  for (int field = 3; field <= 22; ++field) {
    while (pos < stat.size() && stat[pos] == ' ') ++pos;
    const size_t end = stat.find(' ', pos);
    if (field == 22) return stat.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    if (end == std::string::npos) return "";
    pos = end;
  }
  return "";
}

}  // namespace atomic_file_internal

// This process as temporary names record it: "<pid>.<boot>.<start>" (boot: BootTag, start: its
// start time in ticks after boot), or "<pid>" where /proc cannot be read. Why more than the pid:
// after a reboot a dead writer's pid can belong to a live process, whose temporaries are not
// cleared (and a clip the writer was replacing stays hidden); the boot and start time tell that
// process apart from the writer. Made again when the pid changes: a child forked after the first
// call kept its parent's tag, so the two named their temporaries alike (the counter is copied too)
// and the child's were taken for a live process's after it ended.
inline std::string ProcessTag() {
  // Per thread, without a lock: a child forked while another thread held a lock here would wait
  // on it for ever. A thread's cached pid differs from getpid() in a forked child.
  thread_local long tagged_pid = -1;
  thread_local std::string tag;
  const long pid = static_cast<long>(::getpid());
  if (pid != tagged_pid) {
    const std::string boot = atomic_file_internal::BootTag();
    const std::string start = atomic_file_internal::ProcessStartTicks(pid);
    tag = boot.empty() || start.empty() ? std::to_string(pid) : std::to_string(pid) + "." + boot + "." + start;
    tagged_pid = pid;
  }
  return tag;
}

// A temporary name beside `path`, unique within this process and among processes:
// "<path>.tmp-<ProcessTag>-<n>".
inline std::string TemporaryNameFor(const std::string& path) {
  static std::atomic<unsigned long long> counter{0};
  return path + ".tmp-" + ProcessTag() + "-" + std::to_string(counter++);
}

// Whether `name` (a file name) is a temporary TemporaryNameFor gave a process that no longer
// runs: what a crash or Ctrl-C left behind, safe to clear. A live writer's are not. A name
// made in another boot, or whose pid now belongs to a process started at another time, is a
// stopped process's; names with a pid alone (older ones) are judged by the pid.
// Inputs: name, a file or folder name. Outputs: at, where ".tmp-" starts in it (may be null).
inline bool IsTemporaryOfStoppedProcess(const std::string& name, size_t* at = nullptr) {
  const size_t pos = name.rfind(".tmp-");
  if (pos == std::string::npos) return false;
  char* end = nullptr;
  const long pid = std::strtol(name.c_str() + pos + 5, &end, 10);
  if (pid <= 0) return false;
  bool stopped;
  if (*end == '.') {  // "<pid>.<boot>.<start>-<n>"
    const std::string rest(end + 1);
    const size_t dot = rest.find('.'), dash = rest.find('-');
    if (dot == std::string::npos || dash == std::string::npos || dash < dot) return false;
    const std::string boot = rest.substr(0, dot), start = rest.substr(dot + 1, dash - dot - 1);
    const std::string this_boot = atomic_file_internal::BootTag();
    if (!this_boot.empty() && boot != this_boot) {
      stopped = true;  // made before a reboot
    } else if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) {
      stopped = true;
    } else {
      const std::string now = atomic_file_internal::ProcessStartTicks(pid);
      stopped = !now.empty() && now != start;  // the pid reused by a later process
    }
  } else {
    stopped = ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
  }
  if (!stopped) return false;
  if (at) *at = pos;
  return true;
}

// Removes the temporaries TemporaryNameFor gave `path` in processes that no longer run (a run
// killed while it wrote `path`), which nothing else removes: a model's or judge's pair written
// again, a copy of model.pt made again, left a killed run's .tmp files beside them for ever. A
// live writer's stay. For files written now and then (not per frame: it lists the folder).
// `removing` (when set) is told each one's path first. Returns how many went.
inline int RemoveStaleTemporariesOf(const std::string& path,
                                    const std::function<void(const std::string&)>& removing = {}) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const std::string prefix = p.filename().string() + ".tmp-";
  std::error_code ec;
  int removed = 0;
  for (const auto& entry : fs::directory_iterator(p.parent_path().empty() ? fs::path(".") : p.parent_path(), ec)) {
    const std::string name = entry.path().filename().string();
    size_t at = 0;
    if (name.rfind(prefix, 0) == 0 && IsTemporaryOfStoppedProcess(name, &at) && at + 5 == prefix.size()) {
      if (removing) removing(entry.path().string());
      std::error_code ignored;
      removed += fs::remove(entry.path(), ignored) ? 1 : 0;
    }
  }
  return removed;
}

// Writes `bytes` to `path` through a temporary file in the same folder (WriteFileDurably), a
// rename and an fsync of the folder. Throws std::runtime_error naming the file when it fails; the
// temporary is removed then and `path` keeps what it had.
inline void WriteFileAtomically(const std::string& path, const void* data, size_t size) {
  const std::string tmp = TemporaryNameFor(path);
  WriteFileDurably(tmp, data, size);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();  // before remove() reuses an error code ("Success")
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error("cannot rename " + tmp + " to " + path + ": " + why);
  }
  SyncDirectory(std::filesystem::path(path).parent_path().string());
}

inline void WriteFileAtomically(const std::string& path, const std::string& bytes) {
  WriteFileAtomically(path, bytes.data(), bytes.size());
}

// Writes two files that are read as a pair (a model's weights and its model.json): both
// temporaries are written whole before either is renamed into place, and if the second rename
// fails the first file is put back as it was (or removed, if it was not there), so a failure never
// leaves new weights beside an old configuration, which the loader then refuses.
// Inputs: first, second  the paths; first_bytes, second_bytes  their contents; hard_link  makes
// the first file's backup (::link; tests pass one that fails, as on vfat, to reach the copy).
// Throws std::runtime_error naming the file that could not be written or renamed.
inline void WriteFilePairAtomically(const std::string& first, const std::string& first_bytes, const std::string& second,
                                    const std::string& second_bytes,
                                    int (*hard_link)(const char* from, const char* to) = ::link) {
  namespace fs = std::filesystem;
  const std::string tmp_first = TemporaryNameFor(first);
  const std::string tmp_second = TemporaryNameFor(second);
  const std::string backup = TemporaryNameFor(first + ".old");
  std::error_code ignored, ec;
  auto remove_temporaries = [&] {
    for (const std::string* p : {&tmp_first, &tmp_second, &backup}) fs::remove(*p, ignored);
  };
  // A run killed between the two renames left its temporaries and the backup (a torn pair, which
  // the loaders refuse against the copy inside the weights): this write replaces the pair whole.
  for (const std::string& p : {first, second, first + ".old"}) RemoveStaleTemporariesOf(p);
  // The first file's old content is kept under a hard link (a durable copy where the filesystem
  // has none: vfat, exFAT, some network mounts) until the pair is in place. Without it nothing is
  // renamed: a failed second rename would then have no way back.
  const bool had_first = fs::exists(first, ec);
  try {
    WriteFileDurably(tmp_first, first_bytes.data(), first_bytes.size());
    WriteFileDurably(tmp_second, second_bytes.data(), second_bytes.size());
    if (had_first && hard_link(first.c_str(), backup.c_str()) != 0) {
      fs::copy_file(first, backup, ec);
      if (ec) throw std::runtime_error("cannot keep " + first + " aside while its pair is replaced: " + ec.message());
      SyncFile(backup);
    }
  } catch (...) {
    remove_temporaries();
    throw;
  }
  fs::rename(tmp_first, first, ec);
  if (ec) {
    const std::string why = ec.message();
    remove_temporaries();
    throw std::runtime_error("cannot rename " + tmp_first + " to " + first + ": " + why);
  }
  fs::rename(tmp_second, second, ec);
  if (ec) {
    const std::string why = ec.message();
    if (had_first)
      fs::rename(backup, first, ignored);
    else
      fs::remove(first, ignored);
    remove_temporaries();
    SyncDirectory(fs::path(first).parent_path().string());
    throw std::runtime_error("cannot rename " + tmp_second + " to " + second + ": " + why + " (" + first +
                             " is left as it was)");
  }
  if (had_first) fs::remove(backup, ignored);
  SyncDirectory(fs::path(first).parent_path().string());
  if (fs::path(second).parent_path() != fs::path(first).parent_path())
    SyncDirectory(fs::path(second).parent_path().string());
}

// Copies `from` to `to` through a temporary and a rename (WriteFileAtomically): never half a file
// at `to`. Throws std::runtime_error naming `from` when it cannot be read, or `to` when it cannot
// be written.
inline void CopyFileAtomically(const std::string& from, const std::string& to) {
  // A folder opens as a stream, and libstdc++ then throws "basic_filebuf::underflow ... Is a
  // directory" from the read, naming no file.
  std::error_code ec;
  if (std::filesystem::is_directory(from, ec))
    throw std::runtime_error("cannot read " + from + " (a folder, not a file to copy to " + to + ")");
  std::ifstream in(from, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + from + " (to copy it to " + to + ")");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("cannot read " + from + " (to copy it to " + to + ")");
  RemoveStaleTemporariesOf(to);  // a killed copy's (train's model.pt, published again on --resume)
  WriteFileAtomically(to, bytes);
}

// Gives `to` (which must not exist) the content of `from` without copying it: a hard link, where
// the filesystem has them; a durable copy (CopyFileAtomically) where it has none (vfat, exFAT, some
// network mounts). For files that are only ever replaced by a rename, never rewritten in place, so
// the two names cannot come to differ.
// Inputs: from, to  the paths; hard_link  makes the link (::link; tests pass one that fails).
// Throws std::runtime_error naming the file when neither works.
inline void LinkOrCopyFile(const std::string& from, const std::string& to,
                           int (*hard_link)(const char* from, const char* to) = ::link) {
  if (hard_link(from.c_str(), to.c_str()) == 0) return;
  CopyFileAtomically(from, to);
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_ATOMIC_FILE_H_
