// Cost of the clip buffer per camera frame (crop + grey + resize + resampling + assembly) and of
// recording one clip, for the synthetic session's camera and for the paper's 1920x1080 at 60 fps.
// Prints a table; run by hand: <build>/bin/sensors_clip_bench
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include <unistd.h>

#include <opencv2/core.hpp>

#include "bench_args.h"
#include "sensors/clip_pipeline.h"
#include "sensors/dataset_writer.h"

namespace {
using clothwind::sensors::ClipPipeline;
using clothwind::sensors::ClipPipelineOptions;
using clothwind::sensors::ClipSourceEncoding;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

}  // namespace

int Main(int argc, char** argv) {
  if (clothwind::bench::HelpAsked(argc, argv, "Usage: sensors_clip_bench   (no arguments; prints a table)")) return 0;
  if (argc > 1) throw std::invalid_argument(std::string("takes no arguments, got ") + argv[1]);
  std::printf("%-22s %8s %12s %12s %14s\n", "camera", "frames", "ms/frame", "realtime x", "clips");
  struct Case {
    int width, height;
    double fps;
    int frames;
  };
  for (const Case c : {Case{320, 240, 30.0, 900}, Case{1280, 720, 30.0, 300}, Case{1920, 1080, 60.0, 300}}) {
    ClipPipeline p(ClipPipelineOptions{});
    cv::Mat img(c.height, c.width, CV_8UC3);
    cv::randu(img, 0, 255);
    size_t clips = 0;
    const auto t0 = Clock::now();
    for (int i = 0; i < c.frames; ++i) {
      p.AddFrame(1700000000.0 + i / c.fps, img, ClipSourceEncoding::kBgr8);
      clips += p.TakeReady().size();
    }
    clips += p.Flush().size();
    const double s = Seconds(t0, Clock::now());
    char name[64];
    std::snprintf(name, sizeof name, "%dx%d bgr8 @%.0f", c.width, c.height, c.fps);
    std::printf("%-22s %8d %12.3f %12.1f %14zu\n", name, c.frames, 1e3 * s / c.frames, (c.frames / c.fps) / s, clips);
  }

  // Recording: 30 JPEG frames of 300x300 + label.json + index rewrite per clip.
  ClipPipeline p(ClipPipelineOptions{});
  cv::Mat img(240, 320, CV_8UC3);
  cv::randu(img, 0, 255);
  for (int i = 0; i < 36 * 10; ++i) p.AddFrame(1700000000.0 + i / 30.0, img, ClipSourceEncoding::kBgr8);
  const auto clips = p.Flush();
  const std::string root = (std::filesystem::temp_directory_path() / ("clothwind_clip_bench_" + std::to_string(::getpid()))).string();
  clothwind::sensors::DatasetWriter writer(root);
  const auto t0 = Clock::now();
  for (const auto& c : clips) writer.Write(c, {});
  const double s = Seconds(t0, Clock::now());
  std::filesystem::remove_all(root);
  std::printf("record (noise frames, worst case for JPEG): %zu clips, %.1f ms/clip (a clip every 1.2 s)\n", clips.size(),
              1e3 * s / clips.size());
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("sensors_clip_bench", argc, argv, Main); }
