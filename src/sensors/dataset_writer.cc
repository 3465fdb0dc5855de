#include "sensors/dataset_writer.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <set>
#include <utility>
#include <vector>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>

#include "common/atomic_file.h"
#include "common/json_file.h"

namespace clothwind::sensors {
namespace fs = std::filesystem;
namespace {

constexpr int kFormatVersion = 1;

// NaN and inf become null in JSON (nlohmann does that too, but say it explicitly).
nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// A clip's entry in index.json, from its label.json (throws when a field is missing).
nlohmann::json IndexEntry(const std::string& name, const nlohmann::json& label) {
  return {{"name", name},
          {"sequence", label.at("sequence")},
          {"start", label.at("start")},
          {"end", label.at("end")},
          {"num_frames", label.at("num_frames")},
          {"split", label.at("split")},
          {"wind_speed", label.at("wind_speed")},
          {"wind_std", label.at("wind").at("std")},
          {"wind_count", label.at("wind").at("count")}};
}

}  // namespace

void WriteFileAtomically(const std::string& path, const std::string& text) {
  clothwind::WriteFileAtomically(path, text);
}

namespace {

// Whether the clip labelled in `label_path` starts with the camera frame stamped `source_stamp`
// (its label's source_frame_stamps[0]; an unreadable label is taken as another clip's, kept).
bool StartsWithFrame(const std::string& label_path, double source_stamp) {
  try {
    std::ifstream in(label_path);
    if (!in) return false;
    const nlohmann::json label = nlohmann::json::parse(in);
    const auto& stamps = label.at("source_frame_stamps");
    return !stamps.empty() && stamps.at(0).is_number() && stamps.at(0).get<double>() == source_stamp;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

bool IsMountPoint(const std::string& dir) {
  struct stat here {}, parent {};
  std::error_code ec;
  fs::path folder = fs::absolute(dir, ec).lexically_normal();
  if (!folder.has_filename() && folder.has_relative_path()) folder = folder.parent_path();  // "/data/rec/"
  const std::string up = folder.parent_path().string();
  return ::stat(folder.c_str(), &here) == 0 && ::stat(up.empty() ? "/" : up.c_str(), &parent) == 0 &&
         here.st_dev != parent.st_dev;
}

std::string ClipFolderName(double first_stamp) {
  const double whole = std::floor(first_stamp);
  const std::time_t seconds = static_cast<std::time_t>(whole);
  const int millis = std::min(999, static_cast<int>(std::lround((first_stamp - whole) * 1000.0)));
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "clip-%04d%02d%02d-%02d%02d%02d.%03d", tm.tm_year + 1900, tm.tm_mon + 1,
                tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
  return buf;
}

nlohmann::json ClipLabelJson(const LabelledClip& c, const ClipSourceInfo& source, const std::string& name) {
  const auto& frames = c.clip.frames;
  nlohmann::json stamps = nlohmann::json::array(), source_stamps = nlohmann::json::array();
  for (const auto& f : frames) {
    stamps.push_back(f.stamp);
    source_stamps.push_back(f.source_stamp);
  }
  const auto& l = c.label;
  nlohmann::json j;
  j["format"] = "clothwind-clip";
  j["version"] = kFormatVersion;
  j["name"] = name;
  j["kind"] = "real";  // recorded from a camera, as FlagReal (simulated examples say "sim")
  j["split"] = source.split;
  j["sequence"] = c.clip.sequence;
  j["num_frames"] = frames.size();
  j["frame_rate"] = c.frame_rate;
  j["width"] = frames.empty() ? 0 : frames.front().image.cols;
  j["height"] = frames.empty() ? 0 : frames.front().image.rows;
  // The dataset format names colour JPEG frames "rgb8" (as FlagSim's), whatever the byte order in memory.
  j["encoding"] = !frames.empty() && frames.front().image.channels() == 3 ? "rgb8" : "mono8";
  j["frame_pattern"] = "%03d.jpg";
  j["start"] = frames.empty() ? 0.0 : frames.front().stamp;
  j["end"] = frames.empty() ? 0.0 : frames.back().stamp;
  j["frame_stamps"] = stamps;
  j["source_frame_stamps"] = source_stamps;
  j["roi"] = {{"x", c.roi.x}, {"y", c.roi.y}, {"size", c.roi.size}};
  j["source"] = {{"width", c.source_width}, {"height", c.source_height}, {"frame_id", source.frame_id},
                 {"description", source.description}, {"camera_info", source.camera}};
  j["wind_speed"] = Number(l.mean);  // the training target, as in simulated examples
  j["wind"] = {{"window", l.window},          {"end", l.end},
               {"mean", Number(l.mean)},      {"std", Number(l.std)},
               {"count", l.count},            {"direction_mean", Number(l.direction_mean)},
               {"direction_frame_id", source.wind_frame_id},
               {"first_stamp", Number(l.first_stamp)}, {"last_stamp", Number(l.last_stamp)}};
  nlohmann::json sources = nlohmann::json::array();
  for (const WindLabelSource& w : l.sources)
    sources.push_back({{"source", w.source}, {"frame_id", w.frame_id}, {"count", w.count}});
  j["wind"]["sources"] = sources;
  j["wind"]["relative_count"] = l.relative_count;
  return j;
}

DatasetWriter::DatasetWriter(const std::string& root, int jpeg_quality, double index_interval, SteadyNow now)
    : root_(root),
      jpeg_quality_(jpeg_quality),
      index_interval_(index_interval),
      now_(now ? std::move(now) : SteadyNow([] { return std::chrono::steady_clock::now(); })) {
  if (jpeg_quality < 1 || jpeg_quality > 100)
    throw std::invalid_argument("jpeg_quality must be in 1..100, got " + std::to_string(jpeg_quality));
  if (!(index_interval >= 0 && index_interval <= 86400))
    throw std::invalid_argument("index_interval must be in 0..86400 s, got " + std::to_string(index_interval));
  std::error_code ec;
  // Only the folder itself: its parent made here (a USB disk's mount point before the disk came)
  // was later hidden by the disk, whose own index the first clip after the mount replaced.
  // Without its trailing separators: "/data/flagreal/" had "/data/flagreal" itself as its parent,
  // refused for ever as "does not exist (a disk not mounted yet?)".
  fs::path folder = fs::absolute(fs::path(root_)).lexically_normal();
  if (!folder.has_filename() && folder.has_relative_path()) folder = folder.parent_path();
  const fs::path parent = folder.parent_path();
  if (!fs::is_directory(parent, ec))
    throw std::runtime_error("cannot record into " + root_ + ": its parent folder " + parent.string() +
                             " does not exist (a disk not mounted yet?); it is not created");
  fs::create_directory(root_, ec);
  if (ec) throw std::runtime_error("cannot create dataset folder " + root_ + ": " + ec.message());
  // One writer a folder: each rewrites the whole index from what it holds.
  const int fd = ::open((root_ + "/.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + root_ + "/.lock: " + std::strerror(errno));
  lock_.fd = fd;
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    throw std::runtime_error(root_ + " is being recorded into by another writer (" + root_ + "/.lock is held" +
                             (err == EWOULDBLOCK ? "" : std::string(": ") + std::strerror(err)) +
                             "); record into another folder");
  }
  struct stat st{};
  if (::stat(root_.c_str(), &st) == 0) {
    device_ = static_cast<unsigned long long>(st.st_dev);
    inode_ = static_cast<unsigned long long>(st.st_ino);
  }
  const std::string index_path = root_ + "/index.json";
  if (fs::exists(index_path)) {
    std::ifstream in(index_path);
    try {
      index_ = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw std::runtime_error(index_path + ": not valid JSON: " + JsonErrorText(e));
    }
    if (!index_.is_object() || !index_.contains("clips") || !index_["clips"].is_array())
      throw std::runtime_error(index_path + ": expected an object with an array \"clips\"");
    // Every entry an object naming its clip: [1] passed, and every clip's index update then failed
    // (operator[] on a number) while its folder was written, so none ever reached the index.
    const nlohmann::json& clips = index_["clips"];
    for (size_t i = 0; i < clips.size(); ++i) {
      if (!clips[i].is_object() || !clips[i].contains("name") || !clips[i]["name"].is_string())
        throw std::runtime_error(index_path + ": field 'clips[" + std::to_string(i) +
                                 "]' must be an object with a string \"name\", got " + clips[i].dump());
    }
    // Recordings go into a recordings' index only: a make-dataset (FlagSim) index would get real
    // clips listed under its synthetic header.
    if (index_.value("kind", nlohmann::json("real")) != "real")
      throw std::runtime_error(index_path + ": field 'kind' is " + index_.value("kind", nlohmann::json()).dump() +
                               ", expected \"real\" (a folder of recorded clips; record into another folder)");
  } else {
    index_ = {{"format", "clothwind-dataset"}, {"version", kFormatVersion}, {"kind", "real"},
              {"clips", nlohmann::json::array()}};
  }
  recovered_ = RecoverLeftovers();
  reindexed_ = ReindexUnlisted();
  if (reindexed_ > 0) WriteIndex();
}

DatasetWriter::~DatasetWriter() {
  try {
    FlushIndex();
  } catch (const std::exception&) {
    // The clips are in place; the next writer to open the folder lists them.
  }
}

bool DatasetWriter::FlushIndex() {
  if (unlisted_ == 0) return false;
  CheckSameFolder();
  WriteIndex();
  return true;
}

DatasetWriter::LockFile::~LockFile() {
  if (fd >= 0) ::close(fd);  // releases the lock
}

std::string DatasetWriter::FolderLost() const {
  struct stat st{};
  if (::stat(root_.c_str(), &st) != 0)
    return "the dataset folder " + root_ + " is gone (" + std::strerror(errno) + "): recording stopped";
  if (static_cast<unsigned long long>(st.st_dev) != device_ || static_cast<unsigned long long>(st.st_ino) != inode_)
    return "the dataset folder " + root_ + " is no longer the one opened (a disk mounted over it, or the folder "
           "moved): recording stopped, so its index.json is not replaced by this one's";
  return "";
}

void DatasetWriter::CheckSameFolder() const {
  if (const std::string lost = FolderLost(); !lost.empty()) throw std::runtime_error(lost);
}

size_t DatasetWriter::ReindexUnlisted() {
  std::set<std::string> listed;
  for (const auto& c : index_["clips"]) listed.insert(c["name"].get<std::string>());
  std::vector<std::string> found;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(root_, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("clip-", 0) != 0 || listed.count(name) || !entry.is_directory(ec)) continue;
    found.push_back(name);
  }
  std::sort(found.begin(), found.end());  // names sort by time
  size_t added = 0;
  for (const std::string& name : found) {
    try {
      std::ifstream in(root_ + "/" + name + "/label.json");
      const nlohmann::json label = nlohmann::json::parse(in);
      index_["clips"].push_back(IndexEntry(name, label));
      ++added;
    } catch (const std::exception&) {
      // Not a clip this writer made whole (its label.json is written before the folder's
      // rename): left out of the index, as it was.
    }
  }
  return added;
}

std::string DatasetWriter::Write(const LabelledClip& clip, const ClipSourceInfo& source) {
  if (clip.clip.frames.empty()) throw std::invalid_argument("cannot record an empty clip");
  CheckSameFolder();
  // A folder of this name is the same clip when its first camera frame is (a session replayed
  // again: replaced); another clip that starts in the same millisecond (the wall clock stepped
  // back during a live recording, and a new timeline ran over the old) gets a name of its own
  // ("-2", "-3", ...): it silently replaced the recorded clip.
  const std::string base = ClipFolderName(clip.clip.frames.front().stamp);
  std::string name = base;
  for (int k = 2; fs::exists(root_ + "/" + name) &&
                  !StartsWithFrame(root_ + "/" + name + "/label.json", clip.clip.frames.front().source_stamp);
       ++k)
    name = base + "-" + std::to_string(k);
  const std::string final_dir = root_ + "/" + name;
  const std::string tmp_dir = TemporaryNameFor(root_ + "/." + name);
  bool replaced = false;
  std::vector<std::string> problems;  // after the clip is in place
  std::error_code ec;
  fs::create_directory(tmp_dir, ec);
  if (ec) throw std::runtime_error("cannot create " + tmp_dir + ": " + ec.message());
  try {
    const std::vector<int> params{cv::IMWRITE_JPEG_QUALITY, jpeg_quality_};
    std::vector<uchar> jpeg;
    for (size_t i = 0; i < clip.clip.frames.size(); ++i) {
      char file[32];
      std::snprintf(file, sizeof file, "/%03zu.jpg", i);
      if (!cv::imencode(".jpg", clip.clip.frames[i].image, jpeg, params))
        throw std::runtime_error("cannot encode " + tmp_dir + file + " as JPEG");
      WriteFileDurably(tmp_dir + file, jpeg.data(), jpeg.size());
    }
    const nlohmann::json label = ClipLabelJson(clip, source, name);
    // Invalid UTF-8 (a camera's frame_id or distortion model of raw bytes) is written replaced
    // (U+FFFD), not thrown: the throw stopped every later clip's recording.
    WriteFileAtomically(tmp_dir + "/label.json",
                        label.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
    replaced = fs::exists(final_dir);
    if (replaced) {  // replayed again: replace the old folder
      // Two renames, not one: rename() cannot replace a non-empty folder. If the second fails the
      // old copy is put back, so the name never stays empty or hidden.
      const std::string old_dir = TemporaryNameFor(root_ + "/." + name + ".old");
      fs::rename(final_dir, old_dir);
      try {
        fs::rename(tmp_dir, final_dir);
      } catch (...) {
        fs::rename(old_dir, final_dir, ec);
        throw;
      }
      // The clip is in place from here: a failure now is the old copy's, not the clip's (it was
      // counted a failed write, and the index kept the old copy's entry for good).
      fs::remove_all(old_dir, ec);
      if (ec)
        problems.push_back("the copy it replaced, " + old_dir + ", was not removed (" + ec.message() +
                           "; the next opening of the folder removes it)");
    } else {
      fs::rename(tmp_dir, final_dir);
    }
    auto& clips = index_["clips"];
    for (auto it = clips.begin(); it != clips.end(); ++it) {
      if ((*it)["name"] == name) {
        clips.erase(it);
        break;
      }
    }
    clips.push_back(IndexEntry(name, label));
    ++unlisted_;
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(tmp_dir, ec);
    throw std::runtime_error(std::string("recording clip ") + name + ": " + e.what());
  } catch (...) {
    fs::remove_all(tmp_dir, ec);
    throw;
  }
  try {
    SyncDirectory(root_);
  } catch (const std::exception& e) {
    problems.push_back(std::string("its folder's entry may not survive a power cut: ") + e.what());
  }
  const bool index_due = !(index_interval_ > 0 && !replaced && last_index_write_ &&
                           now_() - *last_index_write_ < std::chrono::duration<double>(index_interval_));
  if (index_due) {  // else listed by a later rewrite
    try {
      WriteIndex();
    } catch (const std::exception& e) {
      // The clip is in place and in the index held here: the next index written lists it.
      problems.push_back(root_ + "/index.json not updated (the next clip's update will list it): " + e.what());
    }
  }
  if (!problems.empty()) {
    std::string what = "clip " + name + " recorded, but ";
    for (size_t i = 0; i < problems.size(); ++i) what += (i ? "; and " : "") + problems[i];
    throw ClipRecordedWithAProblem(what);
  }
  return final_dir;
}

size_t DatasetWriter::RecoverLeftovers() {
  // Names this writer gives its temporaries: ".<clip>.tmp-<tag>-<n>" (a clip being written),
  // ".<clip>.old.tmp-<tag>-<n>" (a clip being replaced) and "index.json.tmp-<tag>-<n>", tag the
  // process's (ProcessTag: pid, boot, start time).
  size_t handled = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(root_, ec)) {
    const std::string file = entry.path().filename().string();
    size_t at = 0;
    if (!IsTemporaryOfStoppedProcess(file, &at)) continue;  // not a temporary, or still being written
    // at >= 5: room for "." and ".old" before ".tmp-" (a shorter stray name threw out_of_range,
    // and the writer never started).
    const bool old_copy = at >= 5 && file[0] == '.' && file.compare(at - 4, 4, ".old") == 0;
    const std::string clip = old_copy ? file.substr(1, at - 5) : "";
    if (old_copy && !fs::exists(root_ + "/" + clip)) {
      fs::rename(entry.path(), root_ + "/" + clip, ec);  // a crash between the two renames
    } else {
      fs::remove_all(entry.path(), ec);
    }
    ++handled;
  }
  return handled;
}

void DatasetWriter::WriteIndex() {
  WriteFileAtomically(root_ + "/index.json",
                      index_.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
  unlisted_ = 0;
  last_index_write_ = now_();
}

}  // namespace clothwind::sensors
