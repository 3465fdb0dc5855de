#include "sim/simulate.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <tbb/parallel_for.h>

namespace clothwind::sim {

Theta SceneTheta(const SceneSetup& setup, int cloth) {
  if (cloth < 0 || cloth >= static_cast<int>(setup.cloths.size())) {
    throw std::out_of_range("cloth index " + std::to_string(cloth) + " out of range");
  }
  return ThetaFrom(setup.cloths[cloth].material, setup.wind);
}

Trajectory SimulateTrajectory(const SceneSetup& setup, const Theta& theta,
                              const SimulateOptions& options) {
  if (options.cloth < 0 || options.cloth >= static_cast<int>(setup.cloths.size())) {
    throw std::out_of_range("cloth index " + std::to_string(options.cloth) + " out of range (" +
                            std::to_string(setup.cloths.size()) + " cloths)");
  }
  const auto start = std::chrono::steady_clock::now();
  const ClothSetup& cloth = setup.cloths[options.cloth];
  Material material = cloth.material;
  WindSpec wind = setup.wind;
  ApplyTheta(theta, &material, &wind);
  if (options.seed) wind.SetSeed(*options.seed);

  const double duration = options.duration >= 0 ? options.duration : setup.scene.duration;
  const double frame_time = setup.scene.frame_time;
  // The scene reader's limits: inf went to lround (undefined), 1e9 s overflowed the frame count.
  if (std::isnan(options.duration) || !(std::isfinite(duration) && duration <= 86400 && duration / frame_time <= 1e6)) {
    throw std::invalid_argument("duration must be at most 86400 s and 1e6 frames of " + std::to_string(frame_time) +
                                " s, got " + std::to_string(duration) + " s");
  }
  const int steps_per_frame = setup.scene.frame_steps;
  const int frames = static_cast<int>(std::lround(duration / frame_time));
  // At most an hour (as make-dataset's): 1e8 s overflowed the frame count and ran no warm-up.
  if (!(options.warmup >= 0 && options.warmup <= 3600)) {
    throw std::invalid_argument("warmup must be in 0..3600 s, got " + std::to_string(options.warmup));
  }
  const int warmup_frames = static_cast<int>(std::lround(options.warmup / frame_time));
  const int total = warmup_frames + frames;
  // Gusts over the whole run, warm-up and --duration included, unless the scene set a horizon.
  if (!wind.gusts.horizon_given) wind.gusts.horizon = std::max(wind.gusts.horizon, total * frame_time + 1.0);

  SimOptions sim_options = cloth.options;
  sim_options.wind_density = wind.density;  // the setup's wind may have been edited
  sim_options.wind_drag = wind.drag;
  ClothSimulator sim = StartClothSimulator(cloth, material, sim_options,
                                           options.make_wind ? options.make_wind(wind) : MakeWindField(wind));
  Trajectory t;
  t.faces = cloth.mesh.F;
  t.uv = cloth.mesh.U.cast<float>();
  t.frame_time = frame_time;
  t.frames.reserve(frames + 1);
  auto advance_one_frame = [&] {
    for (int s = 0; s < steps_per_frame; ++s) {
      sim.Step();
      const StepStats& stats = sim.last_step_stats();
      t.solver_iterations += stats.cg_iterations;
      t.strain_limit_sweeps += stats.strain_limit_sweeps;
      if (!stats.strain_limit_converged) ++t.strain_limit_unconverged;
    }
    t.steps += steps_per_frame;
  };
  bool go_on = true;
  for (int f = 1; f <= warmup_frames && go_on; ++f) {
    advance_one_frame();
    if (options.progress) go_on = options.progress(f, total);
  }
  t.frames.push_back(sim.positions().cast<float>());
  for (int f = 1; f <= frames && go_on; ++f) {
    advance_one_frame();
    t.frames.push_back(sim.positions().cast<float>());
    if (options.progress) go_on = options.progress(warmup_frames + f, total);
  }
  t.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return t;
}

std::vector<Trajectory> SimulateTrajectories(const SceneSetup& setup,
                                             const std::vector<Theta>& thetas,
                                             const SimulateOptions& options,
                                             const std::vector<uint64_t>& seeds) {
  if (!seeds.empty() && seeds.size() != thetas.size()) {
    throw std::invalid_argument("SimulateTrajectories: " + std::to_string(seeds.size()) +
                                " seeds for " + std::to_string(thetas.size()) + " thetas");
  }
  std::vector<Trajectory> out(thetas.size());
  std::atomic<int> done{0};
  const int total = static_cast<int>(thetas.size());
  tbb::parallel_for(size_t{0}, thetas.size(), [&](size_t i) {
    SimulateOptions one = options;
    one.progress = nullptr;
    if (!seeds.empty()) one.seed = seeds[i];
    out[i] = SimulateTrajectory(setup, thetas[i], one);
    const int n = ++done;
    if (options.progress) options.progress(n, total);
  });
  return out;
}

}  // namespace clothwind::sim
