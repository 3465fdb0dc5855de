#include "sensors/frame_read_tally.h"

namespace clothwind::sensors {

void FrameReadTally::Record(ReadStatus status, const std::string& error) {
  switch (status) {
    case ReadStatus::kFrame: ++frames_; break;
    case ReadStatus::kBadFrame: BadFrame(error); break;
    case ReadStatus::kError: SourceFailed(error); break;
    case ReadStatus::kNoFrame:
    case ReadStatus::kEnd: break;
  }
}

void FrameReadTally::SourceFailed(const std::string& error) {
  ++failures_;
  last_failure_ = error;
}

void FrameReadTally::BadFrame(const std::string& error) {
  ++bad_frames_;
  last_bad_frame_ = error;
}

std::vector<std::string> FrameReadTally::TakeReport() {
  std::vector<std::string> report;
  if (bad_frames_ > bad_frames_reported_) {
    const uint64_t n = bad_frames_ - bad_frames_reported_;
    report.push_back(std::to_string(n) + (n == 1 ? " frame" : " frames") + " unreadable since last report: " +
                     last_bad_frame_);
  }
  if (failures_ > failures_reported_) {
    const uint64_t n = failures_ - failures_reported_;
    report.push_back(std::to_string(n) + (n == 1 ? " source failure" : " source failures") +
                     " (device lost, reopen failed or recording unreadable) since last report: " + last_failure_);
  }
  bad_frames_reported_ = bad_frames_;
  failures_reported_ = failures_;
  return report;
}

}  // namespace clothwind::sensors
