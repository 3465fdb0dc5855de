// Where a training step's time goes: the spectral layer (with phase steps), the trunk input it
// becomes (pooled or not), and the whole step (forward, loss, backward, Adam), per batch of 16
// clips of 30 frames, for the input sizes and spectral pooling the SDN trains with. Why: the
// layer has no weights but runs on every pixel of every frame, so at a larger input it can
// cost as much as the trunk it feeds (docs/sdn-experiments.md, "Spectra of the full frame"). Prints a table
// of wall and process-CPU milliseconds (medians over --repeats). With --device cuda the clips,
// network and optimiser live on the GPU and each timed call ends in a device synchronisation, so
// wall time is the GPU's (scripts/device-check runs it so on a lent GPU machine).
//
// The layer runs its CPU selection in one pass (learn/spectral_peaks_cpu.h); "tensor ops" times
// the same layer through tensor operations (SpectralOptions::one_pass false, as on a GPU), the
// way it ran before that pass, to show what the pass saves.
//
// "val batch" times a validation batch (eval mode, no gradients) from the clips, and "val from
// images" from their trunk input computed beforehand, as `clothwind train` keeps its validation
// split's images (the layer has no weights), to show what keeping them saves each epoch.
//
// Freed memory is kept for reuse as `clothwind train` keeps it (learn/heap_reuse.h); --glibc-heap
// leaves glibc's defaults, to measure what that saves. --channels-last puts the network's kernels
// in NHWC order (learn::UseChannelsLast, as the Predictor does), to measure what oneDNN's NHWC
// path would save a training step.
//
//   learn_train_step_bench [--repeats N] [--threads T] [--batch B] [--width W] [--device cpu|cuda]
//                          [--cases SIZE:POOL,...] [--glibc-heap] [--channels-last]
//                          (default cases 64:1,96:1,128:2,128:1)

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <torch/cuda.h>
#include <torch/torch.h>

#include "bench_args.h"
#include "bench_clock.h"
#include "omp_wait_policy.h"
#include "learn/heap_reuse.h"
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

// Parses "64:1,128:2" into cases; false on anything else.
bool ParseCases(const std::string& text, std::vector<Case>* cases) {
  cases->clear();
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find(',', start), text.size());
    int size = 0, pool = 0;
    char tail = 0;
    if (std::sscanf(text.substr(start, end - start).c_str(), "%d:%d%c", &size, &pool, &tail) != 2 || size < 8 ||
        pool < 1 || size % pool != 0) {
      return false;
    }
    cases->push_back({size, pool});
    start = end + 1;
  }
  return !cases->empty();
}

// Median wall and CPU time of `repeats` calls of f (after one warm-up call); on a GPU each call
// waits for the device, since kernels run asynchronously.
template <typename F>
Timing Measure(int repeats, bool cuda, F&& f) {
  f();
  if (cuda) torch::cuda::synchronize();
  std::vector<double> wall, cpu;
  for (int r = 0; r < repeats; ++r) {
    const double w0 = WallMs(), c0 = ProcessCpuMs();
    f();
    if (cuda) torch::cuda::synchronize();
    wall.push_back(WallMs() - w0);
    cpu.push_back(ProcessCpuMs() - c0);
  }
  std::nth_element(wall.begin(), wall.begin() + repeats / 2, wall.end());
  std::nth_element(cpu.begin(), cpu.begin() + repeats / 2, cpu.end());
  return {wall[repeats / 2], cpu[repeats / 2]};
}

}  // namespace

int Main(int argc, char** argv) {
  const char* omp_wait_policy = clothwind::bench::EnsureOmpWaitPolicy(argv);
  int repeats = 10, threads = 2, batch = 16, width = 48;
  std::string device_name = "cpu";
  std::vector<Case> cases = {{64, 1}, {96, 1}, {128, 2}, {128, 1}};
  bool ok = true, glibc_heap = false, channels_last = false;
  for (int i = 1; i < argc && ok; ++i) {
    if (!std::strcmp(argv[i], "--glibc-heap")) glibc_heap = true;
    else if (!std::strcmp(argv[i], "--channels-last")) channels_last = true;
    else if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) repeats = std::max(1, clothwind::bench::Integer("--repeats", argv[++i]));
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::max(1, clothwind::bench::Integer("--threads", argv[++i]));
    else if (!std::strcmp(argv[i], "--batch") && i + 1 < argc) batch = std::max(1, clothwind::bench::Integer("--batch", argv[++i]));
    else if (!std::strcmp(argv[i], "--width") && i + 1 < argc) width = std::max(1, clothwind::bench::Integer("--width", argv[++i]));
    else if (!std::strcmp(argv[i], "--device") && i + 1 < argc) device_name = argv[++i];
    else if (!std::strcmp(argv[i], "--cases") && i + 1 < argc) ok = ParseCases(argv[++i], &cases);
    else ok = false;
  }
  if (!ok || (device_name != "cpu" && device_name != "cuda")) {
    std::fprintf(stderr,
                 "usage: learn_train_step_bench [--repeats N] [--threads T] [--batch B] [--width W] [--device cpu|cuda]\n"
                 "                              [--cases SIZE:POOL,...] [--glibc-heap] [--channels-last]  (SIZE >= 8, divisible by POOL >= 1)\n");
    return 2;
  }
  if (!glibc_heap) cl::KeepFreedHeapForReuse();
  const bool cuda = device_name == "cuda";
  if (cuda && !torch::cuda::is_available()) {
    std::fprintf(stderr, "learn_train_step_bench: --device cuda, but libtorch finds no CUDA device\n");
    return 1;
  }
  const at::Device device = cuda ? at::Device(at::kCUDA) : at::Device(at::kCPU);
  at::set_num_threads(threads);
  at::globalContext().setFlushDenormal(true);
  std::printf("SDN training step on %s, batch %d x 30 frames, width %d, k 3, phase steps, %d thread(s), median of %d, OMP_WAIT_POLICY=%s, %s, %s\n",
              device_name.c_str(), batch, width, threads, repeats, omp_wait_policy,
              glibc_heap ? "glibc's default heap" : "freed heap kept for reuse",
              channels_last ? "channels-last kernels" : "default (NCHW) kernels");
  std::printf("%-6s %-5s | %-17s | %-17s | %-17s | %-17s | %-17s | %-17s\n", "input", "pool", "layer wall/cpu ms",
              "tensor ops ms", "trunk input ms", "whole step ms", "val batch ms", "val from images");
  for (const Case& c : cases) {
    cl::ModelConfig config;
    config.arch = "sdn";
    config.frames = 30;
    config.k = 3;
    config.width = width;
    config.phase_steps = true;
    config.input_size = c.input_size;
    config.spectral_pool = c.spectral_pool;
    at::manual_seed(1);
    cl::WindNet net(config);
    net->to(device);
    if (channels_last) cl::UseChannelsLast(*net);
    net->train();
    torch::optim::Adam adam(net->parameters(), torch::optim::AdamOptions(1e-3).weight_decay(1e-4));
    const at::Tensor clips = at::randn({batch, 1, 30, c.input_size, c.input_size}).to(device);
    const at::Tensor target = at::randn({batch}).to(device);
    const Timing layer = Measure(repeats, cuda, [&] {
      at::NoGradGuard no_grad;
      cl::SpectralDecomposition(clips, config.Spectral());
    });
    cl::SpectralOptions tensor_ops = config.Spectral();
    tensor_ops.one_pass = false;
    const Timing layer_tensor_ops = Measure(repeats, cuda, [&] {
      at::NoGradGuard no_grad;
      cl::SpectralDecomposition(clips, tensor_ops);
    });
    const Timing input = Measure(repeats, cuda, [&] {
      at::NoGradGuard no_grad;
      net->TrunkInput(clips);
    });
    const Timing step = Measure(repeats, cuda, [&] {
      adam.zero_grad();
      cl::WindLoss(net->forward(clips), target).backward();
      adam.step();
    });
    // A validation batch: the network in eval mode, from the clips, and from their trunk input
    // images computed beforehand, as training keeps them for its validation split.
    net->eval();
    const Timing val = Measure(repeats, cuda, [&] {
      at::NoGradGuard no_grad;
      net->forward(clips);
    });
    at::Tensor images;
    {
      at::NoGradGuard no_grad;
      images = net->TrunkInput(clips);
    }
    const Timing val_images = Measure(repeats, cuda, [&] {
      at::NoGradGuard no_grad;
      net->ForwardImages(images, batch);
    });
    net->train();
    std::printf("%-6d %-5d | %7.1f / %7.1f | %7.1f / %7.1f | %7.1f / %7.1f | %7.1f / %7.1f | %7.1f / %7.1f | %7.1f / %7.1f\n",
                c.input_size, c.spectral_pool, layer.wall_ms, layer.cpu_ms, layer_tensor_ops.wall_ms,
                layer_tensor_ops.cpu_ms, input.wall_ms, input.cpu_ms, step.wall_ms, step.cpu_ms, val.wall_ms,
                val.cpu_ms, val_images.wall_ms, val_images.cpu_ms);
  }
  return 0;
}

int main(int argc, char** argv) { return clothwind::bench::Guarded("learn_train_step_bench", argc, argv, Main); }
