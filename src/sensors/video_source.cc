#include "sensors/video_source.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "sensors/frame_source_folder.h"

namespace clothwind {
namespace sensors {

VideoFileSource::VideoFileSource(std::string path, double fallback_rate_hz, bool loop,
                                 Clock* clock)
    : path_(std::move(path)), fallback_rate_hz_(fallback_rate_hz), loop_(loop), clock_(clock) {}

bool VideoFileSource::OpenCapture() {
  capture_.release();
  try {
    if (!capture_.open(path_)) return false;
  } catch (const cv::Exception& e) {
    error_ = "video " + path_ + ": " + e.what();
    return false;
  }
  return capture_.isOpened();
}

bool VideoFileSource::Open() {
  Close();
  error_.clear();  // a reason from an earlier open must not be reported for this one
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path_, ec)) {
    error_ = "video file " + path_ + " does not exist or is not a file";
    return false;
  }
  if (!OpenCapture()) {
    if (error_.empty()) error_ = "OpenCV cannot open video " + path_ + " (unknown container/codec?)";
    return false;
  }
  const double file_rate = capture_.get(cv::CAP_PROP_FPS);
  // Containers without a rate report 0 (or nonsense); some report 1000 (ms time base).
  rate_hz_ = (std::isfinite(file_rate) && file_rate > 0 && file_rate < 1000) ? file_rate
                                                                             : fallback_rate_hz_;
  if (!(rate_hz_ > 0)) {
    error_ = "video " + path_ + " reports no frame rate and the fallback rate is not > 0";
    capture_.release();
    return false;
  }
  pacer_ = std::make_unique<FramePacer>(clock_, rate_hz_);
  sequence_ = 0;
  usable_frames_ = 0;
  loops_ = 0;
  open_ = true;
  error_.clear();
  return true;
}

ReadStatus VideoFileSource::Read(Frame* frame, double max_wait_s) {
  if (!open_) {
    error_ = "video " + path_ + " is not open";
    return ReadStatus::kError;
  }
  if (slot_.empty()) {
    cv::Mat raw;
    if (!capture_.read(raw) || raw.empty()) {
      // A file that opens but yields no frame at all (a broken stream, a codec OpenCV lacks) is
      // an error, not an empty recording that ended.
      if (usable_frames_ == 0) {  // not sequence_: bad frames take numbers too
        error_ = "video " + path_ + ": no frame could be decoded (broken file or unsupported codec?)";
        Close();
        return ReadStatus::kError;
      }
      if (!loop_) return ReadStatus::kEnd;
      // Seeking back is unreliable across backends; reopening is not.
      if (!OpenCapture() || !capture_.read(raw) || raw.empty()) {
        error_ = "video " + path_ + ": cannot restart for looping";
        Close();
        return ReadStatus::kError;
      }
      ++loops_;
    }
    Frame f;
    if (!NormalizeRecordedImage(raw, &f.image, &f.encoding)) {
      error_ = "video " + path_ + ": frame " + std::to_string(sequence_) + " has " + std::to_string(raw.channels()) +
               " channels, expected 1, 3 or 4";
      // Its slot and sequence number are kept (the frames after it were stamped a period early).
      ++sequence_;
      slot_.FillBad();
    } else {
      f.sequence = sequence_++;
      ++usable_frames_;
      slot_.Fill(std::move(f));
    }
  }
  return slot_.ReleaseWhenDue(pacer_.get(), max_wait_s, frame);
}

void VideoFileSource::Close() {
  capture_.release();
  open_ = false;
  slot_.Clear();
}

std::string VideoFileSource::Describe() const {
  std::ostringstream s;
  s << "video " << path_ << " @" << rate_hz_ << " Hz" << (loop_ ? ", looping" : "");
  return s.str();
}

std::map<std::string, std::string> VideoFileSource::Status() const {
  return {{"source", "video"},
          {"path", path_},
          {"state", open_ ? "open" : "closed"},
          {"frames read", std::to_string(sequence_)},
          {"loops", std::to_string(loops_)},
          {"rate [Hz]", std::to_string(rate_hz_)}};
}

}  // namespace sensors
}  // namespace clothwind
