// What a camera's reads have done, for diagnostics: frames read, frames that came but could not be
// read, and failures of the source itself. camera_node used to count the last two as one "read
// errors", so a camera unplugged for a minute was reported as dozens of unreadable frames (one per
// failed reopen) and a flaky one as a device that kept failing.
#ifndef CLOTHWIND_SENSORS_FRAME_READ_TALLY_H_
#define CLOTHWIND_SENSORS_FRAME_READ_TALLY_H_

#include <cstdint>
#include <string>
#include <vector>

#include "sensors/frame_source.h"

namespace clothwind::sensors {

class FrameReadTally {
 public:
  // One Read's outcome. Inputs:
  //   status  what FrameSource::Read returned (kNoFrame and kEnd count nothing)
  //   error   the source's error() after it (used for kBadFrame and kError)
  void Record(ReadStatus status, const std::string& error);
  // A frame read but not publishable (its message could not be built): a bad frame.
  void BadFrame(const std::string& error);
  // The source failed outside a Read (FrameSource::Open refused): a failure.
  void SourceFailed(const std::string& error);

  uint64_t frames() const { return frames_; }          // frames read (kFrame)
  uint64_t bad_frames() const { return bad_frames_; }  // frames that came but could not be read
  uint64_t failures() const { return failures_; }      // device lost, reopen failed, recording unreadable
  const std::string& last_bad_frame() const { return last_bad_frame_; }
  const std::string& last_failure() const { return last_failure_; }

  // What changed since the previous call, as warnings for a diagnostics summary, e.g.
  // "3 frames unreadable since last report: <last error>" and "1 source failure (device lost,
  // reopen failed or recording unreadable) since last report: <last error>"; empty when nothing
  // went wrong. Each call starts a new report.
  std::vector<std::string> TakeReport();

 private:
  uint64_t frames_ = 0, bad_frames_ = 0, failures_ = 0;
  uint64_t bad_frames_reported_ = 0, failures_reported_ = 0;
  std::string last_bad_frame_, last_failure_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_FRAME_READ_TALLY_H_
