#ifndef CLOTHWIND_SENSORS_PIXEL_FORMAT_H_
#define CLOTHWIND_SENSORS_PIXEL_FORMAT_H_

#include <cstddef>
#include <cstdint>
#include <string>

#include <opencv2/core/mat.hpp>

namespace clothwind {
namespace sensors {

// The camera pixel formats the capture path understands. Everything is converted to one of the
// two ROS encodings the rest of the pipeline uses: mono8 (GREY) or bgr8 (YUYV, MJPEG).
enum class PixelFormat { kYuyv, kMjpeg, kGrey };

// Parses a user-facing format name ("YUYV", "MJPEG"/"MJPG", "GREY"/"GRAY"/"mono8",
// case-insensitive).
// Inputs:
//   name  format name
// Outputs:
//   format  parsed format (untouched on failure)
//   error   why it failed, naming the expected values
// Returns true on success.
bool ParsePixelFormat(const std::string& name, PixelFormat* format, std::string* error);

// Canonical name of a format ("YUYV", "MJPEG", "GREY").
std::string PixelFormatName(PixelFormat format);

// V4L2 fourcc of a format (V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_GREY).
uint32_t PixelFormatFourcc(PixelFormat format);

// Inverse of PixelFormatFourcc; also accepts V4L2_PIX_FMT_JPEG as MJPEG (some drivers report
// that). Returns false for any other fourcc.
bool PixelFormatFromFourcc(uint32_t fourcc, PixelFormat* format);

// Printable four characters of a fourcc, e.g. "YUYV" (non-printable bytes become '?').
std::string FourccToString(uint32_t fourcc);

// ROS image encoding a format converts to: "mono8" for GREY, "bgr8" otherwise.
std::string RosEncodingFor(PixelFormat format);

// Converts one captured buffer to an image the pipeline can use.
// Inputs:
//   format          pixel format of the buffer
//   data            buffer start
//   bytes_used      valid bytes in the buffer (the compressed size for MJPEG)
//   width, height   image size [px] as negotiated with the driver
//   bytes_per_line  row stride [bytes] (0: tightly packed); ignored for MJPEG
// Outputs:
//   image  height by width CV_8UC1 (GREY) or CV_8UC3 BGR (YUYV, MJPEG); owns its pixels
//   error  why it failed (short buffer, undecodable JPEG, size mismatch)
// Returns true on success.
bool ConvertToImage(PixelFormat format, const uint8_t* data, size_t bytes_used, int width,
                    int height, int bytes_per_line, cv::Mat* image, std::string* error);

}  // namespace sensors
}  // namespace clothwind

#endif  // CLOTHWIND_SENSORS_PIXEL_FORMAT_H_
