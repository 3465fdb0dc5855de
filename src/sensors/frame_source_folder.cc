#include "sensors/frame_source_folder.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <system_error>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/image_file.h"

namespace clothwind {
namespace sensors {
namespace fs = std::filesystem;

bool NormalizeRecordedImage(const cv::Mat& raw, cv::Mat* image, std::string* encoding) {
  cv::Mat eight = raw;
  if (raw.depth() == CV_16U) {
    raw.convertTo(eight, CV_8U, 1.0 / 257.0);
  } else if (raw.depth() != CV_8U) {
    raw.convertTo(eight, CV_8U);
  }
  switch (eight.channels()) {
    case 1: *image = eight; *encoding = "mono8"; return true;
    case 3: *image = eight; *encoding = "bgr8"; return true;
    case 4: cv::cvtColor(eight, *image, cv::COLOR_BGRA2BGR); *encoding = "bgr8"; return true;
    default: return false;
  }
}

namespace {

bool IsImageFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const char* kExts[] = {".png", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm", ".tif", ".tiff"};
  return std::any_of(std::begin(kExts), std::end(kExts), [&](const char* e) { return ext == e; });
}

}  // namespace

ImageFolderSource::ImageFolderSource(std::string folder, double rate_hz, bool loop, Clock* clock)
    : folder_(std::move(folder)), loop_(loop), pacer_(clock, rate_hz) {}

bool ImageFolderSource::Open() {
  Close();
  if (!(pacer_.rate_hz() > 0)) {
    error_ = "image folder " + folder_ + ": rate must be > 0 Hz, got " +
             std::to_string(pacer_.rate_hz());
    return false;
  }
  std::error_code ec;
  if (!fs::is_directory(folder_, ec)) {
    error_ = "image folder " + folder_ + " does not exist or is not a directory";
    return false;
  }
  files_.clear();
  for (const auto& entry : fs::directory_iterator(folder_, ec)) {
    // Names starting with '.' are temporaries of writers that rename into place.
    if (entry.is_regular_file() && IsImageFile(entry.path()) &&
        entry.path().filename().string()[0] != '.') {
      files_.push_back(entry.path().string());
    }
  }
  if (ec) {
    error_ = "image folder " + folder_ + ": " + ec.message();
    return false;
  }
  if (files_.empty()) {
    error_ = "image folder " + folder_ +
             " holds no images (expected .png/.jpg/.jpeg/.bmp/.pgm/.ppm/.tif/.tiff)";
    return false;
  }
  std::sort(files_.begin(), files_.end());
  next_ = 0;
  consecutive_failures_ = 0;
  sequence_ = 0;
  first_cols_ = first_rows_ = 0;
  first_encoding_.clear();
  pacer_.Restart();
  open_ = true;
  error_.clear();
  return true;
}

bool ImageFolderSource::LoadNext(std::string* why) {
  const std::string& file = files_[next_];
  // OpenCV's exceptions (a header claiming more pixels than it allows ended camera_node through
  // std::terminate) and JPEGs cut short (grey rows published as if seen) are unreadable images.
  std::string reason;
  const cv::Mat raw = common::ReadImageFile(file, cv::IMREAD_UNCHANGED, &reason);
  if (raw.empty()) {
    *why = "cannot read image " + file + " (" + reason + ")";
    return false;
  }
  Frame f;
  if (!NormalizeRecordedImage(raw, &f.image, &f.encoding)) {
    *why = "image " + file + " has " + std::to_string(raw.channels()) +
           " channels, expected 1, 3 or 4";
    return false;
  }
  if (first_cols_ == 0) {
    first_cols_ = f.image.cols;
    first_rows_ = f.image.rows;
    first_encoding_ = f.encoding;
  } else if (f.image.cols != first_cols_ || f.image.rows != first_rows_ ||
             f.encoding != first_encoding_) {
    std::ostringstream s;
    s << "image " << file << " is " << f.image.cols << "x" << f.image.rows << " " << f.encoding
      << ", expected " << first_cols_ << "x" << first_rows_ << " " << first_encoding_
      << " like the first image";
    *why = s.str();
    return false;
  }
  f.sequence = sequence_++;
  slot_.Fill(std::move(f));
  ++next_;
  return true;
}

ReadStatus ImageFolderSource::Read(Frame* frame, double max_wait_s) {
  if (!open_) {
    error_ = "image folder " + folder_ + " is not open";
    return ReadStatus::kError;
  }
  if (slot_.empty()) {
    if (next_ >= files_.size()) {
      if (!loop_) return ReadStatus::kEnd;
      next_ = 0;
    }
    std::string why;
    if (!LoadNext(&why)) {
      error_ = why;
      ++next_;  // skip the bad file rather than failing on it forever
      if (++consecutive_failures_ >= files_.size()) {
        // Not one readable image in a whole round (folder deleted?): close, so Open re-lists.
        error_ = "image folder " + folder_ + ": no image readable any more (last: " + why + ")";
        Close();
        return ReadStatus::kError;
      }
      // The image was a frame of the recording: it keeps its slot in time and its sequence number.
      ++sequence_;
      slot_.FillBad();
    } else {
      consecutive_failures_ = 0;
    }
  }
  return slot_.ReleaseWhenDue(&pacer_, max_wait_s, frame);
}

void ImageFolderSource::Close() {
  open_ = false;
  slot_.Clear();
}

std::string ImageFolderSource::Describe() const {
  std::ostringstream s;
  s << "image folder " << folder_ << " (" << files_.size() << " images) @" << pacer_.rate_hz()
    << " Hz" << (loop_ ? ", looping" : "");
  return s.str();
}

std::map<std::string, std::string> ImageFolderSource::Status() const {
  return {{"source", "folder"},
          {"path", folder_},
          {"state", open_ ? "open" : "closed"},
          {"images", std::to_string(files_.size())},
          {"next image", std::to_string(next_)},
          {"frames read", std::to_string(sequence_)},
          {"size", std::to_string(first_cols_) + "x" + std::to_string(first_rows_)},
          {"rate [Hz]", std::to_string(pacer_.rate_hz())}};
}

}  // namespace sensors
}  // namespace clothwind
