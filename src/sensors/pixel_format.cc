#include "sensors/pixel_format.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cctype>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/image_file.h"

namespace clothwind {
namespace sensors {

bool ParsePixelFormat(const std::string& name, PixelFormat* format, std::string* error) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (upper == "YUYV" || upper == "YUY2") {
    *format = PixelFormat::kYuyv;
  } else if (upper == "MJPEG" || upper == "MJPG" || upper == "JPEG") {
    *format = PixelFormat::kMjpeg;
  } else if (upper == "GREY" || upper == "GRAY" || upper == "MONO8" || upper == "Y8") {
    *format = PixelFormat::kGrey;
  } else {
    if (error) *error = "pixel format '" + name + "' is not one of YUYV, MJPEG, GREY";
    return false;
  }
  return true;
}

std::string PixelFormatName(PixelFormat format) {
  switch (format) {
    case PixelFormat::kYuyv: return "YUYV";
    case PixelFormat::kMjpeg: return "MJPEG";
    case PixelFormat::kGrey: return "GREY";
  }
  return "?";
}

uint32_t PixelFormatFourcc(PixelFormat format) {
  switch (format) {
    case PixelFormat::kYuyv: return V4L2_PIX_FMT_YUYV;
    case PixelFormat::kMjpeg: return V4L2_PIX_FMT_MJPEG;
    case PixelFormat::kGrey: return V4L2_PIX_FMT_GREY;
  }
  return 0;
}

bool PixelFormatFromFourcc(uint32_t fourcc, PixelFormat* format) {
  switch (fourcc) {
    case V4L2_PIX_FMT_YUYV: *format = PixelFormat::kYuyv; return true;
    case V4L2_PIX_FMT_MJPEG:
    case V4L2_PIX_FMT_JPEG: *format = PixelFormat::kMjpeg; return true;
    case V4L2_PIX_FMT_GREY: *format = PixelFormat::kGrey; return true;
    default: return false;
  }
}

std::string FourccToString(uint32_t fourcc) {
  std::string s(4, '?');
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xff);
    if (std::isprint(static_cast<unsigned char>(c))) s[i] = c;
  }
  return s;
}

std::string RosEncodingFor(PixelFormat format) {
  return format == PixelFormat::kGrey ? "mono8" : "bgr8";
}

bool ConvertToImage(PixelFormat format, const uint8_t* data, size_t bytes_used, int width,
                    int height, int bytes_per_line, cv::Mat* image, std::string* error) {
  auto fail = [error](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (width <= 0 || height <= 0) return fail("image size must be positive");
  if (data == nullptr || bytes_used == 0) return fail("empty buffer");
  if (format == PixelFormat::kMjpeg) {
    // A frame cut short (USB bandwidth, a bulk transfer lost) still decodes: libjpeg fills the
    // missing rows with grey and only warns. Require the start- and end-of-image markers (some
    // cameras pad the buffer with zeros after the end marker).
    const std::string whole = common::JpegWholeness(data, bytes_used);
    if (!whole.empty()) return fail("MJPEG frame " + whole);
    // One libjpeg pass that keeps its warnings: a frame damaged inside intact markers (a USB
    // transfer corrupted, not lost) decodes into made-up blocks and only warns; cv::imdecode
    // published it.
    cv::Mat decoded;
    const std::string problem = common::DecodeJpegBgr(data, bytes_used, &decoded, width, height);
    if (!problem.empty())
      return fail("MJPEG decode failed (" + std::to_string(bytes_used) + " bytes): " + problem);
    if (decoded.cols != width || decoded.rows != height) {
      return fail("MJPEG frame decodes to " + std::to_string(decoded.cols) + "x" +
                  std::to_string(decoded.rows) + ", negotiated " + std::to_string(width) + "x" +
                  std::to_string(height));
    }
    *image = decoded;
    return true;
  }
  const int bytes_per_pixel = format == PixelFormat::kGrey ? 1 : 2;
  const int stride = bytes_per_line > 0 ? bytes_per_line : width * bytes_per_pixel;
  if (stride < width * bytes_per_pixel) {
    return fail("bytes per line " + std::to_string(stride) + " is less than width*" +
                std::to_string(bytes_per_pixel));
  }
  // The last row only needs its pixels, not its padding.
  const size_t needed = static_cast<size_t>(stride) * (height - 1) +
                        static_cast<size_t>(width) * bytes_per_pixel;
  if (bytes_used < needed) {
    return fail(PixelFormatName(format) + " buffer holds " + std::to_string(bytes_used) +
                " bytes, " + std::to_string(width) + "x" + std::to_string(height) + " needs " +
                std::to_string(needed));
  }
  if (format == PixelFormat::kGrey) {
    const cv::Mat view(height, width, CV_8UC1, const_cast<uint8_t*>(data), stride);
    *image = view.clone();  // the driver's buffer goes back to the queue right after
    return true;
  }
  if (width % 2 != 0) return fail("YUYV needs an even width, got " + std::to_string(width));
  const cv::Mat view(height, width, CV_8UC2, const_cast<uint8_t*>(data), stride);
  cv::Mat bgr;
  cv::cvtColor(view, bgr, cv::COLOR_YUV2BGR_YUYV);
  *image = bgr;
  return true;
}

}  // namespace sensors
}  // namespace clothwind
