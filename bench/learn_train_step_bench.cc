// Where a training step's time goes: the spectral layer (with phase steps), the trunk input it
// becomes (pooled or not), and the whole step (forward, loss, backward, Adam), per batch of 16
// clips of 30 frames, for the input sizes and spectral pooling the SDN trains with. Why: the
// layer has no weights but runs on every pixel of every frame, so at a larger input it can
// cost as much as the trunk it feeds (docs/sdn.md, "Spectra of the full frame"). Prints a table
// of wall and process-CPU milliseconds (medians over --repeats).
//
//   learn_train_step_bench [--repeats N] [--threads T] [--batch B]

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <torch/torch.h>

#include "bench_clock.h"
#include "learn/networks.h"
#include "learn/spectral_layer.h"

namespace cl = clothwind::learn;

namespace {

using clothwind::bench::ProcessCpuMs;
using clothwind::bench::WallMs;

struct Case {
  int input_size, spectral_pool;
};

struct Timing {
  double wall_ms, cpu_ms;
};

// Median wall and CPU time of `repeats` calls of f (after one warm-up call).
template <typename F>
Timing Measure(int repeats, F&& f) {
  f();
  std::vector<double> wall, cpu;
  for (int r = 0; r < repeats; ++r) {
    const double w0 = WallMs(), c0 = ProcessCpuMs();
    f();
    wall.push_back(WallMs() - w0);
    cpu.push_back(ProcessCpuMs() - c0);
  }
  std::nth_element(wall.begin(), wall.begin() + repeats / 2, wall.end());
  std::nth_element(cpu.begin(), cpu.begin() + repeats / 2, cpu.end());
  return {wall[repeats / 2], cpu[repeats / 2]};
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 10, threads = 2, batch = 16;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--batch") && i + 1 < argc) batch = std::max(1, std::atoi(argv[++i]));
    else {
      std::fprintf(stderr, "usage: learn_train_step_bench [--repeats N] [--threads T] [--batch B]\n");
      return 2;
    }
  }
  at::set_num_threads(threads);
  at::globalContext().setFlushDenormal(true);
  const std::vector<Case> cases = {{64, 1}, {96, 1}, {128, 2}, {128, 1}};
  std::printf("SDN training step, batch %d x 30 frames, width 48, k 3, phase steps, %d thread(s), median of %d\n",
              batch, threads, repeats);
  std::printf("%-6s %-5s | %-17s | %-17s | %-17s\n", "input", "pool", "layer wall/cpu ms", "trunk input ms",
              "whole step ms");
  for (const Case& c : cases) {
    cl::ModelConfig config;
    config.arch = "sdn";
    config.frames = 30;
    config.k = 3;
    config.width = 48;
    config.phase_steps = true;
    config.input_size = c.input_size;
    config.spectral_pool = c.spectral_pool;
    at::manual_seed(1);
    cl::WindNet net(config);
    net->train();
    torch::optim::Adam adam(net->parameters(), torch::optim::AdamOptions(1e-3).weight_decay(1e-4));
    const at::Tensor clips = at::randn({batch, 1, 30, c.input_size, c.input_size});
    const at::Tensor target = at::randn({batch});
    const Timing layer = Measure(repeats, [&] {
      at::NoGradGuard no_grad;
      cl::SpectralDecomposition(clips, config.Spectral());
    });
    const Timing input = Measure(repeats, [&] {
      at::NoGradGuard no_grad;
      net->TrunkInput(clips);
    });
    const Timing step = Measure(repeats, [&] {
      adam.zero_grad();
      cl::WindLoss(net->forward(clips), target).backward();
      adam.step();
    });
    std::printf("%-6d %-5d | %7.1f / %7.1f | %7.1f / %7.1f | %7.1f / %7.1f\n", c.input_size, c.spectral_pool,
                layer.wall_ms, layer.cpu_ms, input.wall_ms, input.cpu_ms, step.wall_ms, step.cpu_ms);
  }
  return 0;
}
