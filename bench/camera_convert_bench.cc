// Per-frame cost of turning a captured V4L2 buffer into the image camera_node publishes
// (sensors::ConvertToImage, as camera_node calls it: YUYV -> bgr8 with cv::cvtColor, MJPEG -> bgr8
// with libjpeg through common::DecodeJpegBgr, GREY copy), at common sizes.
// At 30 fps a frame has 33 ms; this shows how much of it conversion takes on this machine.
// Usage: camera_convert_bench [repetitions]   (prints a table)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_args.h"
#include "sensors/pixel_format.h"

namespace {

using clothwind::sensors::ConvertToImage;
using clothwind::sensors::PixelFormat;
using clothwind::sensors::PixelFormatName;

// A textured scene (a flag-like gradient with noise) so JPEG sizes are realistic.
cv::Mat Scene(int w, int h) {
  cv::Mat bgr(h, w, CV_8UC3);
  cv::RNG rng(1);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uint8_t>((c * 255) / w),
                                          static_cast<uint8_t>(128 + 100 * std::sin(r * 0.05 + c * 0.03)),
                                          static_cast<uint8_t>(rng.uniform(0, 60)));
  return bgr;
}

std::vector<uint8_t> Buffer(PixelFormat f, const cv::Mat& bgr) {
  if (f == PixelFormat::kMjpeg) {
    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
    return jpeg;
  }
  if (f == PixelFormat::kGrey) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    return std::vector<uint8_t>(grey.data, grey.data + grey.total());
  }
  // YUYV: Y per pixel, U and V shared by pixel pairs (BT.601, enough for timing).
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YUV);
  std::vector<uint8_t> out(bgr.total() * 2);
  for (int r = 0; r < bgr.rows; ++r)
    for (int c = 0; c < bgr.cols; c += 2) {
      const cv::Vec3b a = yuv.at<cv::Vec3b>(r, c), b = yuv.at<cv::Vec3b>(r, c + 1);
      uint8_t* p = &out[(static_cast<size_t>(r) * bgr.cols + c) * 2];
      p[0] = a[0]; p[1] = static_cast<uint8_t>((a[1] + b[1]) / 2);
      p[2] = b[0]; p[3] = static_cast<uint8_t>((a[2] + b[2]) / 2);
    }
  return out;
}

}  // namespace

int Main(int argc, char** argv) {
  if (clothwind::bench::HelpAsked(argc, argv, "Usage: camera_convert_bench [repetitions]   (prints a table)")) return 0;
  const int reps = clothwind::bench::OptionalCount(argc, argv, "repetitions", 50, 1);
  cv::setNumThreads(1);  // the node converts on its capture thread
  std::printf("%-6s %-10s %10s %12s %10s\n", "format", "size", "bytes", "ms/frame", "max fps");
  const std::vector<std::pair<int, int>> sizes{{640, 480}, {1280, 720}, {1920, 1080}};
  for (PixelFormat f : {PixelFormat::kYuyv, PixelFormat::kMjpeg, PixelFormat::kGrey}) {
    for (const auto& [w, h] : sizes) {
      const cv::Mat scene = Scene(w, h);
      const std::vector<uint8_t> buf = Buffer(f, scene);
      cv::Mat out;
      std::string error;
      if (!ConvertToImage(f, buf.data(), buf.size(), w, h, 0, &out, &error)) {
        std::fprintf(stderr, "%s %dx%d: %s\n", PixelFormatName(f).c_str(), w, h, error.c_str());
        return 1;
      }
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < reps; ++i) ConvertToImage(f, buf.data(), buf.size(), w, h, 0, &out, &error);
      const double ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count() / reps;
      std::printf("%-6s %4dx%-5d %10zu %12.3f %10.0f\n", PixelFormatName(f).c_str(), w, h, buf.size(), ms,
                  1000.0 / ms);
    }
  }
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("camera_convert_bench", argc, argv, Main); }
