#ifndef CLOTHWIND_SENSORS_CLIP_PREPROCESS_H_
#define CLOTHWIND_SENSORS_CLIP_PREPROCESS_H_

#include <string>

#include <opencv2/core.hpp>

namespace clothwind::sensors {

// Pixel layouts a camera frame may arrive in (sensor_msgs/Image encodings the clip buffer takes).
enum class ClipSourceEncoding { kMono8, kMono16, kBgr8, kRgb8, kBgra8, kRgba8 };

// Parses a sensor_msgs/Image encoding name ("mono8", "bgr8", ...). Throws std::invalid_argument
// naming the encoding and the accepted ones when it is not supported.
ClipSourceEncoding ParseClipSourceEncoding(const std::string& encoding);

// OpenCV type (CV_8UC3, ...) of an image in the given encoding.
int ClipSourceCvType(ClipSourceEncoding encoding);

// A square region of interest in source pixels: columns [x, x + size), rows [y, y + size).
// size <= 0 means "the centred square of side min(width, height)".
struct SquareRoi {
  int x = 0;
  int y = 0;
  int size = 0;
};

// Resolves a requested roi against a source image size.
// Inputs:
//   requested  roi as configured (size <= 0: centred square)
//   width, height  source image size [px] > 0
// Returns the roi in source pixels. Throws std::invalid_argument when the square does not fit in
// the image (the message gives the roi and the image size).
SquareRoi ResolveRoi(const SquareRoi& requested, int width, int height);

// Turns one camera frame into one clip frame the way the paper prepared its real videos: square
// crop around the flag, greyscale (ITU-R BT.601 luma, as cv::cvtColor), area-averaged resize
// (anti-aliased downsampling) to out_size x out_size. With `colour` the frame keeps its colour
// (BGR) for a model that reads Y, Cr and Cb (learn::ModelConfig::colour).
// Inputs:
//   image     rows x cols source frame, type ClipSourceCvType(encoding)
//   encoding  its pixel layout (mono16 is scaled by 1/256 to 8 bits)
//   roi       resolved square roi (ResolveRoi) inside the image
//   out_size  side of the output frame [px] > 0 (300)
//   colour    false: grey output; true: BGR output (a grey source repeated in all three channels)
// Returns an out_size x out_size ClipFrameCvType(colour) image (a new buffer, never a view of the
// input).
cv::Mat PreprocessClipFrame(const cv::Mat& image, ClipSourceEncoding encoding, const SquareRoi& roi,
                            int out_size, bool colour = false);

// Type of a clip frame: CV_8UC1 (mono8) grey, CV_8UC3 (bgr8) colour.
int ClipFrameCvType(bool colour);

// ROS encoding of a clip frame: "mono8" grey, "bgr8" colour.
const char* ClipFrameEncoding(bool colour);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CLIP_PREPROCESS_H_
