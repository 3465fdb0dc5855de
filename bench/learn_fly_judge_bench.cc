// What telling the way a flag flies costs per clip, on the 30 frames of 64x64 grey a model reads:
// the motion cues (learn/fly_direction.h) against the learned judge (learn/fly_judge.h), and the
// judge as sdn_node runs it: from the clip's 300 px crops, each resized to the judge's own side
// first (learn/dataset.cc TurnsToFlyRight), which costs more than judging.
//   build/bin/learn_fly_judge_bench [--judge models/fly_judge.pt] [Google Benchmark flags]
// Without --judge a judge of random weights of the shipped shape (64 hidden units) is timed; a
// --judge file that is missing is an error (its rows were labelled with the path while random
// weights were timed). Denormal floats are flushed to zero, as the node's Predictor does
// on its thread: the shipped judge holds denormal weights (a quarter of its hidden layer), whose
// arithmetic otherwise took over half the time measured.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <ATen/Context.h>
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench_args.h"
#include "learn/dataset.h"
#include "learn/fly_direction.h"
#include "learn/fly_judge.h"
#include "learn/heap_reuse.h"

namespace {

using clothwind::learn::FlyJudge;

std::string g_judge_path;

// A flag held at the left of a 64 px square, its ripples growing toward the fly end.
std::vector<cv::Mat> Clip() {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0, 2);
  std::vector<cv::Mat> frames;
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(64, 64, CV_8UC1);
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        const double v = 120 + 60.0 * x / 64 * std::sin(0.4 * x - 0.6 * t + 0.1 * y) + noise(rng);
        f.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(v);
      }
    }
    frames.push_back(f);
  }
  return frames;
}

FlyJudge Judge() {
  if (!g_judge_path.empty()) return FlyJudge::Load(g_judge_path);  // main checked it exists
  std::mt19937_64 rng(2);
  std::normal_distribution<float> n(0.0f, 0.1f);
  Eigen::MatrixXf w1(64, clothwind::learn::kMotionMapGrid * clothwind::learn::kMotionMapGrid);
  Eigen::VectorXf b1(64), w2(64);
  for (int i = 0; i < w1.size(); ++i) w1.data()[i] = n(rng);
  for (int i = 0; i < 64; ++i) b1[i] = n(rng), w2[i] = n(rng);
  return FlyJudge(w1, b1, w2, 0.0f);
}

void BM_MotionCues(benchmark::State& state) {
  const std::vector<cv::Mat> clip = Clip();
  for (auto _ : state) benchmark::DoNotOptimize(clothwind::learn::EstimateFlyDirection(clip).score);
}
BENCHMARK(BM_MotionCues)->Unit(benchmark::kMicrosecond);

void BM_FlyJudge(benchmark::State& state) {
  const std::vector<cv::Mat> clip = Clip();
  const FlyJudge judge = Judge();
  double score = 0;
  for (auto _ : state) benchmark::DoNotOptimize(judge.Judge(clip, &score));
  state.SetLabel(g_judge_path.empty() ? "random weights" : g_judge_path);
}
BENCHMARK(BM_FlyJudge)->Unit(benchmark::kMicrosecond);

// The node's path: 30 crops of 300x300 (clip_buffer's default side), each resized to the judge's
// map side, then judged.
void BM_FlyJudgeFromNodeCrops(benchmark::State& state) {
  std::vector<cv::Mat> crops;
  for (const cv::Mat& f : Clip()) {
    cv::Mat big;
    cv::resize(f, big, cv::Size(300, 300), 0, 0, cv::INTER_LINEAR);
    crops.push_back(big);
  }
  const FlyJudge judge = Judge();
  std::vector<cv::Mat> small(crops.size());
  double score = 0;
  for (auto _ : state) {
    for (size_t t = 0; t < crops.size(); ++t)
      clothwind::learn::ResizeCrop(crops[t], cv::Rect(0, 0, 300, 300), clothwind::learn::kMotionMapSide, small[t]);
    benchmark::DoNotOptimize(judge.Judge(small, &score));
  }
  state.SetLabel(g_judge_path.empty() ? "random weights" : g_judge_path);
}
BENCHMARK(BM_FlyJudgeFromNodeCrops)->Unit(benchmark::kMicrosecond);

void BM_MotionMapOnly(benchmark::State& state) {
  const std::vector<cv::Mat> clip = Clip();
  for (auto _ : state) benchmark::DoNotOptimize(clothwind::learn::MotionMap(clip).data);
}
BENCHMARK(BM_MotionMapOnly)->Unit(benchmark::kMicrosecond);

}  // namespace

int Main(int argc, char** argv) {
  // --judge FILE is ours; everything else is Google Benchmark's.
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    if (std::strcmp(argv[i], "--judge") == 0) {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "learn_fly_judge_bench: --judge: expected a judge file (e.g. models/fly_judge.pt)\n");
        return 2;
      }
      g_judge_path = argv[++i];
    } else if (std::strncmp(argv[i], "--judge=", 8) == 0) {
      g_judge_path = argv[i] + 8;
    } else {
      rest.push_back(argv[i]);
    }
  }
  // Checked before any timing: a missing judge used to time random weights under its path.
  std::error_code ec;
  if (!g_judge_path.empty() && !std::filesystem::is_regular_file(g_judge_path, ec)) {
    std::fprintf(stderr, "learn_fly_judge_bench: --judge %s: no such file (expected a judge, e.g. models/fly_judge.pt)\n",
                 g_judge_path.c_str());
    return 2;
  }
  // A judge that does not load is named too, not timed as random weights.
  if (!g_judge_path.empty()) {
    try {
      (void)FlyJudge::Load(g_judge_path);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "learn_fly_judge_bench: --judge %s: %s\n", g_judge_path.c_str(), e.what());
      return 2;
    }
  }
  // Every benchmark from the same heap state: with glibc returning freed memory to the kernel,
  // BM_FlyJudge took 2.4 ms run alone and 0.1 ms after BM_MotionCues. sdn_node leaves glibc's
  // defaults (only `train` calls this); glibc raises its mmap threshold when the first large
  // blocks are freed, so a node reading clip after clip comes near this steady state, but its
  // first clips can cost more than these figures.
  clothwind::learn::KeepFreedHeapForReuse();
  at::globalContext().setFlushDenormal(true);
  int n = static_cast<int>(rest.size());
  benchmark::Initialize(&n, rest.data());
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("learn_fly_judge_bench", argc, argv, Main); }
