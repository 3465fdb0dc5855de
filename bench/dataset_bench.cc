// Dataset generation speed: CPU ms per 300x300 frame on one core for each stage (simulation,
// rendering, JPEG), the CPU seconds of one 60-frame clip, and the clips per minute that follow
// for N cores; then a real `make-dataset` run on all cores (wall clock). Prints a table.
//
//   dataset_bench [--kind flag|cloth] [--count N] [--views K] [--jobs J] [--max-edge M] [--samples S]
//
// CPU time is per thread (CLOCK_THREAD_CPUTIME_ID), so the per-core figures hold on a machine
// shared with other work; the wall-clock run shows what the machine delivered at the time.

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include "bench_args.h"
#include "bench_clock.h"
#include "data/cloth_animation.h"
#include "data/dataset_generator.h"
#include "data/example_sampling.h"
#include "data/paths.h"
#include "render/renderer.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"
#include "sim/simulate.h"

namespace cd = clothwind::data;
namespace cr = clothwind::render;
namespace cs = clothwind::sim;

using clothwind::bench::ThreadCpuSeconds;
using clothwind::bench::WallMs;

int Main(int argc, char** argv) {
  std::string kind_name = "flag";
  int count = 4, views = 2, jobs = 0;
  double max_edge = 0.0;
  int samples = clothwind::data::DatasetOptions().samples;
  for (int i = 1; i < argc; ++i) {
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "dataset_bench: %s needs a value\n", argv[i]);
        std::exit(2);
      }
      return argv[++i];
    };
    if (!std::strcmp(argv[i], "--kind")) kind_name = next();
    else if (!std::strcmp(argv[i], "--count")) count = clothwind::bench::Integer("--count", next());
    else if (!std::strcmp(argv[i], "--views")) views = clothwind::bench::Integer("--views", next());
    else if (!std::strcmp(argv[i], "--jobs")) jobs = clothwind::bench::Integer("--jobs", next());
    else if (!std::strcmp(argv[i], "--max-edge")) max_edge = clothwind::bench::Number("--max-edge", next());
    else if (!std::strcmp(argv[i], "--samples")) samples = clothwind::bench::Integer("--samples", next());
    else {
      std::fprintf(stderr, "usage: dataset_bench [--kind flag|cloth] [--count N] [--views K] [--jobs J] [--max-edge M] [--samples S]\n");
      return 2;
    }
  }
  if (kind_name != "flag" && kind_name != "cloth") {  // SceneKindFromName's throw ended the bench with abort()
    std::fprintf(stderr, "dataset_bench: --kind must be flag or cloth, got '%s'\n", kind_name.c_str());
    return 2;
  }
  const cr::SceneKind kind = cr::SceneKindFromName(kind_name);
  cd::DatasetOptions o;  // the defaults of make-dataset
  const int frames = o.frames;
  const double warmup = o.warmup;

  // 1. One example's stages on this thread.
  cs::BuildOptions build;
  build.max_edge = max_edge;
  const cs::SceneSetup base = cs::BuildScene(cs::LoadScene(cd::DefaultScenePath(kind), [](const std::string&) {}), build);
  cd::SimulationSample s;
  std::vector<cd::Fabric> fabrics;
  if (kind == cr::SceneKind::kFlag) {
    s = cd::SampleFlagSimulation(cs::SceneTheta(base), 1, 0, cd::DefaultRanges(kind));
  } else {
    fabrics = cd::LoadFabrics(cd::DefaultMaterialsDir(), cd::DefaultScenePath(kind), o.exclude_fabrics);
    s = cd::SampleClothSimulation(fabrics, 1, 0, cd::DefaultRanges(kind));
  }
  cs::SceneSetup setup = base;
  if (!fabrics.empty()) setup.cloths[0].material = fabrics[s.fabric_index].material;
  setup.wind.velocity = s.wind_velocity.norm() > 0 ? s.wind_velocity : Eigen::Vector3d::UnitX();
  cs::SimulateOptions so;
  const int first = static_cast<int>(std::lround(warmup / base.scene.frame_time));
  so.duration = (first + frames - 1) * base.scene.frame_time;
  double t0 = ThreadCpuSeconds();
  const cs::Trajectory traj = cs::SimulateTrajectory(setup, s.theta, so);
  const double sim_s = ThreadCpuSeconds() - t0;
  const cd::ClothAnimation anim = cd::AnimationFromTrajectory(traj, first, frames);

  cr::RenderParams zeta = cd::SampleView(kind, s.seed, 0, 1);
  if (samples > 0) zeta.samples = samples;
  cr::RenderOptions ro;
  ro.threads = 1;
  t0 = ThreadCpuSeconds();
  cr::Renderer renderer(zeta, ro);
  const std::vector<cv::Mat> images = cd::RenderAnimation(&renderer, anim, 0.0, frames, 25.0);
  const double render_s = ThreadCpuSeconds() - t0;
  t0 = ThreadCpuSeconds();
  size_t bytes = 0;
  for (const auto& im : images) {
    std::vector<uint8_t> buf;
    cv::imencode(".jpg", im, buf, {cv::IMWRITE_JPEG_QUALITY, 95});
    bytes += buf.size();
  }
  const double jpeg_s = ThreadCpuSeconds() - t0;

  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  std::printf("dataset_bench: %s, %d vertices, %d faces, %.1f s warm-up + %d frames (%.1f s simulated, "
              "time step %.4f s), %dx%d, %d samples/pixel, %s %s\n",
              kind_name.c_str(), traj.num_vertices(), traj.num_faces(), warmup, frames, so.duration,
              setup.cloths[0].options.dt, zeta.width, zeta.height, zeta.samples, zeta.texture_kind.c_str(),
              zeta.texture_name.c_str());
  std::printf("%-34s %12s %14s\n", "stage (one core)", "CPU s/clip", "CPU ms/frame");
  std::printf("%-34s %12.3f %14.2f\n", "simulate (incl. warm-up)", sim_s, 1e3 * sim_s / frames);
  std::printf("%-34s %12.3f %14.2f\n", "render 300x300", render_s, 1e3 * render_s / frames);
  std::printf("%-34s %12.3f %14.2f   (%.0f kB/frame)\n", "JPEG encode (q95)", jpeg_s, 1e3 * jpeg_s / frames,
              bytes / 1024.0 / frames);
  for (int k : views > 1 ? std::vector<int>{1, views} : std::vector<int>{1}) {  // one row when --views 1
    const double clip = sim_s / k + render_s + jpeg_s;
    std::printf("%-34s %12.3f %14.2f   -> %.1f clips/min on 1 core, %.1f on 2 cores, %.1f on %u\n",
                (std::string("one clip, ") + std::to_string(k) + " view(s) per simulation").c_str(), clip,
                1e3 * clip / frames, 60.0 / clip, 120.0 / clip, cores * 60.0 / clip, cores);
  }
  std::printf("60-frame clip rendered (render + JPEG) on one core: %.2f s CPU\n", render_s + jpeg_s);

  // 2. A real run (wall clock, all stages, files written).
  const std::string dir = "/tmp/dataset_bench_" + std::to_string(::getpid());
  o.kind = kind;
  o.count = count;
  o.views = views;
  o.out = dir;
  o.jobs = jobs;
  o.max_edge = max_edge;
  o.samples = samples;
  o.contact_sheet = false;
  const double w0 = WallMs();
  const cd::DatasetSummary sum = cd::GenerateDataset(o);
  const double wall = (WallMs() - w0) * 1e-3;  // [s]
  std::printf("make-dataset run: %lld simulations x %d views = %lld clips in %.1f s wall on %d jobs: "
              "%.1f clips/min (worker time: simulate %.1f s, render %.1f s, write %.1f s)\n",
              static_cast<long long>(sum.simulated), views, static_cast<long long>(sum.examples_written), wall,
              sum.jobs, 60.0 * sum.examples_written / wall, sum.simulate_seconds, sum.render_seconds,
              sum.write_seconds);
  std::filesystem::remove_all(dir);
  return sum.failed > 0 ? 1 : 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("dataset_bench", argc, argv, Main); }
