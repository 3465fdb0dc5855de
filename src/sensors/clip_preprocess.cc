#include "sensors/clip_preprocess.h"

#include <algorithm>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace clothwind::sensors {

namespace {

// Resizes a square crop to out_size x out_size: INTER_AREA averages the source pixels under each
// output pixel when shrinking (no aliasing of the fine flag texture); enlarging is bilinear.
cv::Mat ResizeSquare(const cv::Mat& crop, int out_size) {
  cv::Mat out;
  if (crop.cols == out_size) {
    out = crop.clone();
  } else {
    cv::resize(crop, out, cv::Size(out_size, out_size), 0, 0,
               crop.cols > out_size ? cv::INTER_AREA : cv::INTER_LINEAR);
  }
  return out;
}

// The crop's pixels as a clip frame's: 8-bit grey, or BGR with `colour` (grey repeated).
cv::Mat ToClipPixels(const cv::Mat& crop, ClipSourceEncoding encoding, bool colour) {
  cv::Mat eight = crop;
  if (encoding == ClipSourceEncoding::kMono16) crop.convertTo(eight, CV_8U, 1.0 / 256.0);
  int code = -1;  // no conversion
  switch (encoding) {
    case ClipSourceEncoding::kMono8:
    case ClipSourceEncoding::kMono16: code = colour ? cv::COLOR_GRAY2BGR : -1; break;
    case ClipSourceEncoding::kBgr8: code = colour ? -1 : cv::COLOR_BGR2GRAY; break;
    case ClipSourceEncoding::kRgb8: code = colour ? cv::COLOR_RGB2BGR : cv::COLOR_RGB2GRAY; break;
    case ClipSourceEncoding::kBgra8: code = colour ? cv::COLOR_BGRA2BGR : cv::COLOR_BGRA2GRAY; break;
    case ClipSourceEncoding::kRgba8: code = colour ? cv::COLOR_RGBA2BGR : cv::COLOR_RGBA2GRAY; break;
  }
  if (code < 0) return eight;
  cv::Mat out;
  cv::cvtColor(eight, out, code);
  return out;
}

}  // namespace

ClipSourceEncoding ParseClipSourceEncoding(const std::string& encoding) {
  if (encoding == "mono8" || encoding == "8UC1") return ClipSourceEncoding::kMono8;
  if (encoding == "mono16" || encoding == "16UC1") return ClipSourceEncoding::kMono16;
  if (encoding == "bgr8" || encoding == "8UC3") return ClipSourceEncoding::kBgr8;
  if (encoding == "rgb8") return ClipSourceEncoding::kRgb8;
  if (encoding == "bgra8" || encoding == "8UC4") return ClipSourceEncoding::kBgra8;
  if (encoding == "rgba8") return ClipSourceEncoding::kRgba8;
  throw std::invalid_argument("image encoding '" + encoding +
                              "' not supported; expected mono8, mono16, bgr8, rgb8, bgra8 or rgba8");
}

int ClipSourceCvType(ClipSourceEncoding encoding) {
  switch (encoding) {
    case ClipSourceEncoding::kMono8: return CV_8UC1;
    case ClipSourceEncoding::kMono16: return CV_16UC1;
    case ClipSourceEncoding::kBgr8:
    case ClipSourceEncoding::kRgb8: return CV_8UC3;
    case ClipSourceEncoding::kBgra8:
    case ClipSourceEncoding::kRgba8: return CV_8UC4;
  }
  return -1;
}

SquareRoi ResolveRoi(const SquareRoi& requested, int width, int height) {
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("roi: image size " + std::to_string(width) + "x" +
                                std::to_string(height) + " is empty");
  if (requested.size <= 0) {
    const int side = std::min(width, height);
    return {(width - side) / 2, (height - side) / 2, side};
  }
  if (requested.x < 0 || requested.y < 0 || requested.x + requested.size > width ||
      requested.y + requested.size > height)
    throw std::invalid_argument("roi [x=" + std::to_string(requested.x) + ", y=" +
                                std::to_string(requested.y) + ", size=" + std::to_string(requested.size) +
                                "] does not fit in a " + std::to_string(width) + "x" +
                                std::to_string(height) + " image");
  return requested;
}

int ClipFrameCvType(bool colour) { return colour ? CV_8UC3 : CV_8UC1; }

const char* ClipFrameEncoding(bool colour) { return colour ? "bgr8" : "mono8"; }

cv::Mat PreprocessClipFrame(const cv::Mat& image, ClipSourceEncoding encoding, const SquareRoi& roi,
                            int out_size, bool colour) {
  if (out_size <= 0) throw std::invalid_argument("clip frame size must be > 0, got " + std::to_string(out_size));
  if (image.type() != ClipSourceCvType(encoding))
    throw std::invalid_argument("image type does not match its encoding");
  const SquareRoi r = ResolveRoi(roi, image.cols, image.rows);
  // Crop first (a view, no copy) so colour conversion only touches the pixels we keep.
  const cv::Mat crop = image(cv::Rect(r.x, r.y, r.size, r.size));
  return ResizeSquare(ToClipPixels(crop, encoding, colour), out_size);
}

}  // namespace clothwind::sensors
