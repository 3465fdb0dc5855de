#ifndef CLOTHWIND_SENSORS_FRAME_SOURCE_FOLDER_H_
#define CLOTHWIND_SENSORS_FRAME_SOURCE_FOLDER_H_

#include <string>
#include <vector>

#include "sensors/frame_source.h"

namespace clothwind {
namespace sensors {

// Frames from a folder of images (png, jpg, jpeg, bmp, pgm, ppm, tif, tiff), in filename order
// (zero-pad the numbers: frame_0009 sorts before frame_0010), played at a fixed rate.
// Single-channel images become mono8, colour ones bgr8 (alpha dropped, 16-bit scaled to 8).
// All images must have the size and channel count of the first one, as a camera would.
// Stamps are the instants the frames are due (see FramePacer), in ROS time.
class ImageFolderSource : public FrameSource {
 public:
  // Inputs:
  //   folder   directory to read
  //   rate_hz  frames per second (> 0)
  //   loop     start over after the last image instead of ending
  //   clock    clocks (not owned)
  ImageFolderSource(std::string folder, double rate_hz, bool loop, Clock* clock);

  // Lists the folder. Fails if it does not exist, is not a directory or holds no images.
  bool Open() override;
  ReadStatus Read(Frame* frame, double max_wait_s) override;
  void Close() override;
  bool IsOpen() const override { return open_; }
  std::string error() const override { return error_; }
  std::string Describe() const override;
  double NominalRate() const override { return pacer_.rate_hz(); }
  std::map<std::string, std::string> Status() const override;

  // The image files found by Open, sorted.
  const std::vector<std::string>& files() const { return files_; }

 private:
  bool LoadNext(std::string* why);

  std::string folder_;
  bool loop_;
  FramePacer pacer_;
  std::vector<std::string> files_;
  size_t next_ = 0;
  size_t consecutive_failures_ = 0;
  uint64_t sequence_ = 0;
  bool open_ = false;
  PacedFrameSlot slot_;  // the next image, or an unreadable one, waiting for its due instant
  int first_cols_ = 0, first_rows_ = 0;
  std::string first_encoding_;
  std::string error_;
};

// Converts an image as read from a file (any depth, 1/3/4 channels) to mono8 or bgr8.
// Inputs:
//   raw  image from cv::imread(IMREAD_UNCHANGED) or cv::VideoCapture
// Outputs:
//   image     CV_8UC1 or CV_8UC3 BGR
//   encoding  "mono8" or "bgr8"
// Returns false if the channel count is not 1, 3 or 4.
bool NormalizeRecordedImage(const cv::Mat& raw, cv::Mat* image, std::string* encoding);

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_FRAME_SOURCE_FOLDER_H_
