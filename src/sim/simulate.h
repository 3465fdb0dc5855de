#ifndef CLOTHWIND_SIM_SIMULATE_H_
#define CLOTHWIND_SIM_SIMULATE_H_

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "sim/parameters.h"
#include "sim/scene_builder.h"
#include "sim/trajectory_io.h"

namespace clothwind::sim {

struct SimulateOptions {
  double duration = -1.0;        // simulated seconds recorded; < 0: the scene's duration
  // Simulated seconds run before frame 0 is recorded (rounded to whole frames), e.g. to let the
  // flag's release from its flat start die out before a clip; time (and the wind) runs on.
  double warmup = 0.0;
  std::optional<uint64_t> seed;  // seeds the wind's turbulence and gusts (WindSpec::SetSeed)
  int cloth = 0;                 // which of the scene's cloths (each is simulated alone)
  // Called after every frame with (frames done, frames total); return false to stop early
  // (the trajectory then holds the frames done so far). May be empty.
  std::function<bool(int, int)> progress;
  // Builds the wind field from the wind spec (after theta's wind speed and the seed are applied).
  // Empty: MakeWindField. The sim-to-real work plugs further effects in here (e.g. wrap the
  // standard field with a wake or a measured gust record); must be thread-safe when batched.
  std::function<std::shared_ptr<const WindField>(const WindSpec&)> make_wind;
};

// Simulates one cloth of a scene with parameter vector theta (area weight, bending table, wind
// speed: parameters.h) and returns the frames in memory: frame 0 is the state after the warm-up
// (the initial state without one), then one frame every frame_time for the duration
// (round(duration / frame_time) + 1 frames). Progress counts warm-up and recorded frames.
//
// Thread-safe: `setup` is only read; concurrent calls share nothing mutable. Deterministic: the
// same setup, theta and seed give bit-identical frames, on any thread.
//
// Inputs:
//   setup    scene loaded by BuildScene (its `wind` gives direction, shear, turbulence, gusts)
//   theta    17 parameters (ValidateTheta)
//   options  duration, seed, cloth, progress
// Returns the trajectory (with steps and wall time filled in).
Trajectory SimulateTrajectory(const SceneSetup& setup, const Theta& theta,
                              const SimulateOptions& options = {});

// Runs SimulateTrajectory for every theta in parallel (TBB), results in input order.
// options.progress, if set, is called as (simulations done, total) and must be thread-safe;
// each simulation gets seeds[i] if given (seeds.size() == thetas.size()), else options.seed.
std::vector<Trajectory> SimulateTrajectories(const SceneSetup& setup,
                                             const std::vector<Theta>& thetas,
                                             const SimulateOptions& options = {},
                                             const std::vector<uint64_t>& seeds = {});

// The scene's own theta (its material and wind) for cloth `cloth`.
Theta SceneTheta(const SceneSetup& setup, int cloth = 0);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_SIMULATE_H_
