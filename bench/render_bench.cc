// Renderer speed: ms per 300x300 frame on one thread and on all threads, and 60-frame clips
// per minute, for a procedurally waving flag of about 1000 vertices. Prints a table.
//
//   render_bench [--frames N] [--samples S] [--seed K] [--write DIR] [--cloth]
//
// --write DIR also saves the frames of the all-threads run as PNG (to look at them), after the
// timing.

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "bench_args.h"
#include "bench_clock.h"
#include "render/render_params.h"
#include "render/renderer.h"
#include "render/sensor_model.h"
#include "render/test_meshes.h"

namespace cr = clothwind::render;

namespace {
using clothwind::bench::ProcessCpuMs;
using clothwind::bench::WallMs;

struct Timing {
  double wall_ms, cpu_ms;  // per frame, setup included
  double setup_cpu_ms;     // Renderer construction (textures, backdrop, static scene)
  double setup_wall_ms;
  // Setup and the first frame (which also builds the cache of static radiance), and the mean of
  // every later frame: a 60-frame clip is the one plus 59 of the other. (Spreading the first
  // frame's cache over 60 frames held only for --frames 60: --frames 3 gave 2.6 s a clip, 60
  // gave 1.0 s.)
  double first_cpu_ms, first_wall_ms;
  double later_cpu_ms = 0, later_wall_ms = 0;  // 0 with one frame
  int frames = 0;
  double ClipCpuMs() const { return first_cpu_ms + 59.0 * later_cpu_ms; }
  double ClipWallMs() const { return first_wall_ms + 59.0 * later_wall_ms; }
};

// Renders a clip of `frames` frames at 25 fps; returns the mean wall and CPU ms per frame. The
// frames are written to `write_dir` (when given) after the timing, which it does not include.
Timing RunClip(const cr::RenderParams& p, int threads, int frames, const std::string& write_dir) {
  // Everything a clip costs: textures, backdrop, static geometry and the first frame's cache
  // of static radiance are built inside the timed region.
  const double t0 = WallMs(), c0 = ProcessCpuMs();
  cr::RenderOptions o;
  o.threads = threads;
  cr::Renderer r(p, o);
  const double setup = ProcessCpuMs() - c0, setup_wall = WallMs() - t0;
  const double w = p.mesh_width, h = p.MeshRestHeight();
  std::vector<cv::Mat> rendered;
  double first_cpu = 0, first_wall = 0;
  for (int i = 0; i < frames; ++i) {
    const cr::ClothMesh m = p.scene == cr::SceneKind::kFlag
                                ? cr::WavingFlag(39, 26, w, h, i / p.fps)
                                : cr::HangingCloth(32, 32, w, h, i / p.fps);
    cv::Mat frame = r.RenderFrame(m.V, m.F, m.UV);
    if (!write_dir.empty()) rendered.push_back(frame);
    if (i == 0) first_cpu = ProcessCpuMs() - c0, first_wall = WallMs() - t0;
  }
  Timing t{(WallMs() - t0) / frames, (ProcessCpuMs() - c0) / frames, setup, setup_wall, first_cpu, first_wall};
  t.frames = frames;
  if (frames > 1) {
    t.later_cpu_ms = (t.cpu_ms * frames - first_cpu) / (frames - 1);
    t.later_wall_ms = (t.wall_ms * frames - first_wall) / (frames - 1);
  }
  for (size_t i = 0; i < rendered.size(); ++i) {
    char name[64];
    std::snprintf(name, sizeof(name), "/frame_%03zu.png", i);
    cr::WriteFrameAtomic(write_dir + name, rendered[i]);
  }
  return t;
}
}  // namespace

int Main(int argc, char** argv) {
  int frames = 60, samples = 4;
  uint64_t seed = 1;
  std::string write_dir;
  bool cloth = false;
  for (int i = 1; i < argc; ++i) {
    auto next = [&](const char* flag) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "render_bench: %s needs a value\n", flag);
        std::exit(2);
      }
      return argv[++i];
    };
    if (!std::strcmp(argv[i], "--frames")) frames = clothwind::bench::Integer("--frames", next("--frames"));
    else if (!std::strcmp(argv[i], "--samples")) samples = clothwind::bench::Integer("--samples", next("--samples"));
    else if (!std::strcmp(argv[i], "--seed")) {
      const std::string text = next("--seed");
      size_t used = 0;
      try {
        seed = std::stoull(text, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != text.size() || text[0] == '-')
        throw std::invalid_argument("--seed: expected a whole number >= 0, got '" + text + "'");
    }
    else if (!std::strcmp(argv[i], "--write")) write_dir = next("--write");
    else if (!std::strcmp(argv[i], "--cloth")) cloth = true;
    else {
      std::fprintf(stderr,
                   "usage: render_bench [--frames N] [--samples S] [--seed K] [--write DIR] "
                   "[--cloth]\n");
      return 2;
    }
  }
  if (frames < 2 || samples < 1) {
    // Two frames at least: a clip's cost is its first frame (with the caches it builds) and the
    // frames after it.
    std::fprintf(stderr, "render_bench: --frames must be >= 2 and --samples >= 1\n");
    return 2;
  }
  if (!write_dir.empty()) std::filesystem::create_directories(write_dir);
  cr::RenderParams p = cr::SampleRenderParams(cloth ? cr::SceneKind::kCloth : cr::SceneKind::kFlag, seed);
  p.samples = samples;
  const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
  std::printf("render_bench: %dx%d, %d samples/pixel, %s mesh (flag 39x26 = 1014, cloth 32x32 = 1024 "
              "vertices), %d frames, "
              "texture %s, seed %llu\n",
              p.width, p.height, samples, cloth ? "cloth" : "flag", frames,
              p.texture_name.c_str(), static_cast<unsigned long long>(seed));
  std::printf("zeta: %s\n", cr::ToJson(p).dump().c_str());
  const Timing one = RunClip(p, 1, frames, "");
  const Timing all = RunClip(p, 0, frames, write_dir);
  // Clips per minute from CPU time: what the machine delivers when nobody else uses it.
  std::printf("%-12s %14s %14s %22s\n", "threads", "wall ms/frame", "CPU ms/frame",
              "clips(60)/min (CPU)");
  std::printf("%-12s %14.2f %14.2f %22.1f\n", "1", one.wall_ms, one.cpu_ms,
              60000.0 / one.ClipCpuMs());
  std::printf("%-12s %14.2f %14.2f %22.1f\n", (std::to_string(hw) + " (all)").c_str(),
              all.wall_ms, all.cpu_ms, hw * 60000.0 / all.ClipCpuMs());
  std::printf("per clip, before the first frame: %.1f ms CPU (textures, backdrop, scene); the first frame "
              "with it: %.1f ms CPU, each later frame %.2f ms CPU\n",
              one.setup_cpu_ms, one.first_cpu_ms, one.later_cpu_ms);
  std::printf("one 60-frame clip on one core: %.2f s CPU (%.2f s wall)\n", one.ClipCpuMs() / 1000.0,
              one.ClipWallMs() / 1000.0);
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("render_bench", argc, argv, Main); }
