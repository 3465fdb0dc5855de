// Wind network inference latency per clip as sdn_node sees it: 30 frames of 300x300 mono8 in
// (bgr8 for a colour model, converted to YCrCb as the node does), crop/resize/normalise +
// forward pass, for the SDN and the frame-stack baseline at several widths and input sizes, on 1
// and 2 threads (the goal: <= 50 ms per 30-frame clip on 2 cores at the shipped size: time it
// with `--model models/sdn.pt --flag-flies auto`, as sdn_node reads it; the default cases are other
// sizes, without phase steps). Models are initialised in a temporary folder (speed does not depend
// on the weights). "threads" are torch's (OpenCV's resize uses its own pool). Prints a table.
// --model benches given trained models (e.g. the shipped models/sdn.pt) instead of the
// initialised ones. Clips are read as filmed (--flag-flies right) unless --flag-flies says
// otherwise: auto adds judging each clip's way (with the fly judge beside a model when there is
// one), as sdn_node does for a model trained without flips (learn/fly_direction.h). (Before
// 2026-12-05 the default was the model's own, auto for the shipped model: its "as filmed" rows
// judged too.) The row names the way. The convolutions run in
// channels-last order, as the Predictor runs them on the CPU; --both-orders times each model in
// torch's default order too (column "order": nhwc, nchw), to show what that order saves.
//
//   sdn_bench [--repeats N] [--quick] [--model PATH.pt ...] [--flag-flies right|left|auto] [--both-orders]

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bench_args.h"
#include "bench_clock.h"
#include "omp_wait_policy.h"
#include "learn/predictor.h"
#include "learn/train.h"

namespace cl = clothwind::learn;
namespace fs = std::filesystem;

namespace {

using clothwind::bench::ProcessCpuMs;
using clothwind::bench::WallMs;

struct Case {
  std::string arch;
  int width, input_size, frames;
};

}  // namespace

int Main(int argc, char** argv) {
  const char* omp_wait_policy = clothwind::bench::EnsureOmpWaitPolicy(argv);
  int repeats = 20;
  bool quick = false;
  std::vector<fs::path> given;
  std::string flag_flies;
  bool both_orders = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::max(1, clothwind::bench::Integer("--repeats", argv[++i]));
    else if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--model") && i + 1 < argc) given.push_back(argv[++i]);
    else if (!std::strcmp(argv[i], "--flag-flies") && i + 1 < argc) flag_flies = argv[++i];
    else if (!std::strcmp(argv[i], "--both-orders")) both_orders = true;
    else {
      std::fprintf(stderr,
                   "usage: sdn_bench [--repeats N] [--quick] [--model PATH.pt ...] [--flag-flies right|left|auto] "
                   "[--both-orders]\n");
      return 2;
    }
  }
  // Before the cases are made and timed: a missing model ended the run with SIGABRT after them.
  for (const fs::path& model : given)
    if (!fs::is_regular_file(model)) throw std::invalid_argument("--model " + model.string() + ": no such file");
  cl::FlagFlies way = cl::FlagFlies::kRight;
  try {
    if (!flag_flies.empty()) way = cl::FlagFliesFromName(flag_flies, "--flag-flies");
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "sdn_bench: %s\n", e.what());
    return 2;
  }
  std::vector<Case> cases = {{"sdn", 32, 64, 30},  {"sdn", 16, 112, 30},       {"sdn", 32, 112, 30},
                             {"sdn", 64, 112, 30}, {"resnet18", 64, 112, 30}, {"sdn", 64, 224, 30}};
  if (quick) cases = {{"sdn", 16, 112, 30}, {"sdn", 64, 112, 30}};
  if (!given.empty()) cases.clear();
  const fs::path dir = fs::temp_directory_path() / ("clothwind_sdn_bench_" + std::to_string(::getpid()));
  // A clip as the node receives it: 30 frames 300x300 of moving stripes, mono8 for grey models
  // and bgr8 (red and green stripes) for colour ones, which the node converts to YCrCb per clip.
  std::vector<cv::Mat> grey_frames, bgr_frames;
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(300, 300, CV_8UC1);
    for (int y = 0; y < 300; ++y)
      for (int x = 0; x < 300; ++x) f.at<uint8_t>(y, x) = static_cast<uint8_t>(128 + 100 * std::sin(0.05 * x + 0.9 * t));
    grey_frames.push_back(f);
    cv::Mat bgr;
    cv::merge(std::vector<cv::Mat>{cv::Mat::zeros(f.size(), CV_8UC1), 255 - f, f}, bgr);
    bgr_frames.push_back(bgr);
  }
  std::printf("OMP_WAIT_POLICY=%s\n", omp_wait_policy);
  std::printf("%-28s %7s %5s %10s %10s %10s %14s\n", "model", "threads", "order", "mean [ms]", "p90 [ms]",
              "min [ms]", "cpu/clip [ms]");
  std::vector<fs::path> models = given;
  for (const Case& c : cases) {
    cl::TrainOptions o;
    o.model.arch = c.arch;
    o.model.width = c.width;
    o.model.input_size = c.input_size;
    o.model.frames = c.frames;
    o.out = dir / (c.arch + std::to_string(c.width) + "_" + std::to_string(c.input_size));
    o.init_only = true;
    o.threads = 1;
    models.push_back(cl::Train(o).model);
  }
  for (const fs::path& model : models) {
    for (int threads : {1, 2}) {
      for (bool channels_last : both_orders ? std::vector<bool>{true, false} : std::vector<bool>{true}) {
        cl::Predictor p(model, threads, "cpu", channels_last);
        p.set_flag_flies(way);
        const bool colour = p.config().colour;
        const std::vector<cv::Mat>& clip = colour ? bgr_frames : grey_frames;
        p.PredictFrames(cl::CameraFramesForModel(clip, colour));  // warm-up, as the node does
        std::vector<double> ms;
        const double cpu0 = ProcessCpuMs();
        for (int i = 0; i < repeats; ++i) {
          const double t0 = WallMs();
          p.PredictFrames(cl::CameraFramesForModel(clip, colour));
          ms.push_back(WallMs() - t0);
        }
        const double cpu = (ProcessCpuMs() - cpu0) / repeats;
        std::sort(ms.begin(), ms.end());
        double mean = 0;
        for (double m : ms) mean += m;
        mean /= ms.size();
        const std::string name = p.config().Name() + " " + cl::FlagFliesName(way);
        std::printf("%-28s %7d %5s %10.1f %10.1f %10.1f %14.1f\n", name.c_str(), threads,
                    channels_last ? "nhwc" : "nchw", mean, ms[(9 * ms.size() + 9) / 10 - 1], ms.front(),
                    cpu);
        std::fflush(stdout);
      }
    }
  }
  fs::remove_all(dir);
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("sdn_bench", argc, argv, Main); }
