#ifndef CLOTHWIND_SENSORS_VIDEO_SOURCE_H_
#define CLOTHWIND_SENSORS_VIDEO_SOURCE_H_

#include <memory>
#include <string>

#include <opencv2/videoio.hpp>

#include "sensors/frame_source.h"

namespace clothwind {
namespace sensors {

// Frames from a video file through cv::VideoCapture, played at the file's native rate (or
// fallback_rate_hz when the container does not say). Stamps are the instants the frames are due
// (see FramePacer), in ROS time; they keep increasing across loops.
class VideoFileSource : public FrameSource {
 public:
  // Inputs:
  //   path              video file
  //   fallback_rate_hz  rate used when the file reports none [Hz]
  //   loop              start over at the end instead of ending
  //   clock             clocks (not owned)
  VideoFileSource(std::string path, double fallback_rate_hz, bool loop, Clock* clock);

  bool Open() override;
  ReadStatus Read(Frame* frame, double max_wait_s) override;
  void Close() override;
  bool IsOpen() const override { return open_; }
  std::string error() const override { return error_; }
  std::string Describe() const override;
  double NominalRate() const override { return rate_hz_; }
  std::map<std::string, std::string> Status() const override;

 private:
  bool OpenCapture();

  std::string path_;
  double fallback_rate_hz_;
  bool loop_;
  Clock* clock_;
  double rate_hz_ = 0;
  std::unique_ptr<FramePacer> pacer_;
  cv::VideoCapture capture_;
  bool open_ = false;
  PacedFrameSlot slot_;  // the next frame, or an undecodable one, waiting for its due instant
  uint64_t sequence_ = 0;
  uint64_t usable_frames_ = 0;  // frames decoded and usable since Open (a file with none is an error)
  int loops_ = 0;
  std::string error_;
};

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_VIDEO_SOURCE_H_
