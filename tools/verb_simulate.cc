// clothwind simulate SCENE.json --out DIR: runs an ArcSim scene through our cloth simulator and
// writes ArcSim-style frame OBJs (0000_00.obj = frame 0, cloth 0), the binary trajectory
// (sim/trajectory_io.h) and summary.json.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "output_paths.h"
#include "sim/mesh.h"
#include "sim/parameters.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"
#include "sim/simulate.h"
#include "sim/trajectory_io.h"
#include "sim/turbulent_wind.h"
#include "progress_bar.h"
#include "stale_frames.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

namespace fs = std::filesystem;

struct SimulateArgs {
  std::string scene;
  std::string out;
  double duration = 0;     // [s]; read only when given (duration_given)
  bool duration_given = false;
  std::string wind;        // "VX,VY,VZ"
  std::string turbulence;  // "I,L"
  int64_t seed = 0;        // read only when given (seed_given)
  bool seed_given = false;
  double max_edge = 0;
  int frame_steps = 0;
  double warmup = 0;
  std::vector<std::string> params;  // "name=value"
  bool no_obj = false;
};

std::vector<double> ParseList(const std::string& text, size_t n, const std::string& flag) {
  // getline drops a last empty item: "1,2,3," read as three numbers.
  if (!text.empty() && text.back() == ',')
    throw UsageError(flag + ": expected " + Num(n) + " comma-separated numbers, got '" + text + "' (a trailing comma)");
  std::vector<double> v;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError(flag + ": '" + item + "' is not a number");
    }
    if (!std::isfinite(v.back())) throw UsageError(flag + ": values must be finite");
  }
  if (v.size() != n) {
    throw UsageError(flag + ": expected " + Num(n) +
                                " comma-separated numbers, got '" + text + "'");
  }
  return v;
}

std::string FrameName(int frame, int cloth) {
  char name[32];
  std::snprintf(name, sizeof(name), "%04d_%02d.obj", frame, cloth);
  return name;
}

int Run(const SimulateArgs& a) {
  RefuseUnwritableOutputFolder("--out", a.out);
  // Named as the option (the builder's own check said "BuildOptions.max_edge must be ...").
  if (!(std::isfinite(a.max_edge) && a.max_edge >= 0))
    throw UsageError("--max-edge must be a finite length >= 0 m (0: the scene's resolution), got " +
                     Num(a.max_edge));
  // The scene's warnings (ArcSim keys ignored, features not simulated) are said and kept in
  // summary.json: stderr is easily lost in a batch, and they change the physics.
  std::vector<std::string> scene_warnings;
  const sim::Scene scene = sim::LoadScene(a.scene, [&](const std::string& warning) {
    std::fprintf(stderr, "warning: %s\n", warning.c_str());
    scene_warnings.push_back(warning);
  });
  sim::BuildOptions build;
  build.max_edge = a.max_edge;
  build.frame_steps = a.frame_steps;
  sim::SceneSetup setup = sim::BuildScene(scene, build);
  // The mesh simulated, which ArcSim's adaptive remeshing would not have been: its size sets the
  // cost (ArcSim's flag at remeshing.size [5 mm, 50 mm] became 53,633 vertices, hours of work,
  // said only by the progress bar's time left).
  for (size_t c = 0; c < setup.cloths.size(); ++c) {
    const sim::ClothSetup& cloth = setup.cloths[c];
    std::fprintf(stderr, "simulate: cloths[%zu]: %lld vertices, %lld faces", c,
                 static_cast<long long>(cloth.mesh.V.rows()), static_cast<long long>(cloth.mesh.F.rows()));
    if (cloth.mesh.V.rows() != cloth.original_vertices)
      std::fprintf(stderr, ", the OBJ's %d refined once to edges of at most %.3g m", cloth.original_vertices,
                   cloth.max_edge);
    if (scene.cloths[c].remeshing.present && a.max_edge == 0)
      std::fprintf(stderr, " (from remeshing.size; ArcSim's adaptive remeshing is not simulated: docs/scenes.md)");
    std::fprintf(stderr, "\n");
  }
  if (!a.wind.empty()) {
    const auto v = ParseList(a.wind, 3, "--wind");
    setup.wind.velocity = Eigen::Vector3d(v[0], v[1], v[2]);
    // The scene reader's bound (3x the speed of sound); stableNorm: 1e200 squared is infinite.
    if (!(setup.wind.velocity.stableNorm() <= 1000))
      throw UsageError("--wind: expected a speed of at most 1000 m/s, got " + a.wind);
  }
  if (!a.turbulence.empty()) {
    const auto v = ParseList(a.turbulence, 2, "--turbulence");
    // The scene reader's bounds (sim/turbulent_wind.h): 50,1 or 0.1,1e-300 failed steps later
    // naming neither the option nor the value, after the earlier run in --out was removed.
    if (!(v[0] >= 0 && v[0] <= sim::kMaxTurbulenceIntensity && v[1] >= sim::kMinTurbulenceLengthScale &&
          v[1] <= sim::kMaxTurbulenceLengthScale))
      throw UsageError("--turbulence: expected I in 0..10 and L in 0.01..10000 m, got " + a.turbulence);
    setup.wind.turbulence.intensity = v[0];
    setup.wind.turbulence.length_scale = v[1];
  }
  sim::SimulateOptions options;
  // Checked here, naming the option, before anything in --out is removed (SimulateTrajectory's
  // own check came after, and named no option); a whole number of frames, as make-dataset's: a
  // warm-up of 0.03 s at 0.04 s frames ran as 0.04 s without a word.
  if (!(a.warmup >= 0 && a.warmup <= 3600))
    throw UsageError("--warmup must be in 0..3600 s, got " + Num(a.warmup));
  if (std::abs(a.warmup / scene.frame_time - std::round(a.warmup / scene.frame_time)) > 1e-6)
    throw UsageError("--warmup must be a whole number of " + a.scene + "'s frames (a multiple of " +
                                Num(scene.frame_time) + " s), got " + Num(a.warmup) + " s");
  options.warmup = a.warmup;
  // "Not given" is told by the option's count, not a value: --seed -1 and --duration -1 (the old
  // sentinels) ran as if not given, where any other negative was refused.
  if (a.seed_given && a.seed < 0) throw UsageError("--seed must be >= 0, got " + Num(a.seed));
  if (a.seed_given) options.seed = static_cast<uint64_t>(a.seed);
  // NaN used to fall through to the scene's duration and inf to undefined behaviour.
  if (a.duration_given && !(std::isfinite(a.duration) && a.duration > 0 && a.duration <= 86400)) {
    throw UsageError("--duration must be a time > 0 and <= 86400 s, got " + Num(a.duration));
  }
  if (a.duration_given) options.duration = a.duration;  // else SimulateOptions' default: the scene's
  // The scene's own bound on its frames (held in memory, then copied to write the trajectory):
  // a day at the flag's 0.04 s was 2.16 million frames.
  if (a.duration_given && !(a.duration / scene.frame_time <= 1e6)) {
    throw UsageError("--duration " + Num(a.duration) + " s is " +
                                Num(a.duration / scene.frame_time) + " frames of " + a.scene +
                                "'s frame_time " + Num(scene.frame_time) + " s; at most 1e6");
  }
  // Every cloth's theta, checked before anything of an earlier run is removed: a --param typo
  // used to be refused only after the old run's frames and summary were gone.
  std::map<int, double> given;  // --param's index -> value
  for (const auto& p : a.params) {
    const auto eq = p.find('=');
    if (eq == std::string::npos) throw UsageError("--param: expected NAME=VALUE, got '" + p + "'");
    const int index = [&] {
      try {
        return sim::ParameterIndex(p.substr(0, eq));
      } catch (const std::exception& e) {
        throw UsageError(std::string("--param: ") + e.what());
      }
    }();
    if (given.count(index))
      throw UsageError("--param " + p.substr(0, eq) + " is given twice (the last would silently win)");
    given[index] = ParseList(p.substr(eq + 1), 1, "--param " + p)[0];
  }
  std::vector<sim::Theta> thetas;
  for (int c = 0; c < static_cast<int>(setup.cloths.size()); ++c) {
    sim::Theta theta = sim::SceneTheta(setup, c);
    for (const auto& [index, value] : given) theta[index] = value;
    try {
      sim::ValidateTheta(theta);
    } catch (const std::invalid_argument& e) {
      if (given.empty()) throw;  // the scene's own values: an input refused, not the command line
      throw UsageError(std::string("with --param: ") + e.what());
    }
    thetas.push_back(theta);
  }
  // Taken away again, while still empty, when the run fails before writing (MadeFolders).
  const MadeFolders out_folders = MakeFoldersFor("--out", fs::path(a.out) / "summary.json");
  // summary.json marks a finished run (scripts/window-oracle reuses a folder that has one): the
  // old run's goes before new frames are written, so a run stopped midway leaves none.
  {
    std::error_code ec;
    fs::remove(fs::path(a.out) / "summary.json", ec);
    if (ec) throw std::runtime_error("cannot remove the old " + (fs::path(a.out) / "summary.json").string() + ": " + ec.message());
  }
  // Every frame OBJ and trajectory of an earlier run goes too (this run writes all of its own):
  // kept, a --no-obj run or one with fewer cloths left the old run's frames and trajectory_<c>
  // beside the new summary, and `render DIR --obj` (or --cloth c) rendered the old cloth.
  {
    const int stale = RemoveStaleFrames(
        a.out, [](const std::string& name) {
          return ObjFrameAndCloth(name) || IsSimulateTrajectory(name) || IsTemporaryOfStoppedProcess(name);
        });
    if (stale > 0)
      std::fprintf(stderr, "simulate: removed %d frame OBJs, trajectories and temporaries left by an earlier run\n", stale);
  }

  nlohmann::json summary;
  summary["scene"] = scene.path;
  summary["scene_warnings"] = scene_warnings;
  summary["cloths"] = nlohmann::json::array();
  double total_wall = 0;
  const sim::Theta& theta0 = thetas[0];
  for (int c = 0; c < static_cast<int>(setup.cloths.size()); ++c) {
    const sim::Theta& theta = thetas[c];
    options.cloth = c;
    ProgressBar::Options bar_options;
    bar_options.label = "simulate";
    bar_options.unit = "frames";
    bar_options.rate_scale = scene.frame_time;
    bar_options.rate_unit = "sim s/s";
    ProgressBar bar(bar_options);
    options.progress = [&bar](int done, int total) { return bar.Update(done, total); };
    // A failure mid-run (a blow-up) names the scene and cloth: its message names a step and a
    // vertex, and a scene's values are what the user can change.
    const sim::Trajectory t = [&] {
      try {
        return sim::SimulateTrajectory(setup, theta, options);
      } catch (const std::exception& e) {
        throw std::runtime_error(scene.path + ", cloths[" + Num(c) + "]: " + e.what());
      }
    }();
    total_wall += t.wall_seconds;
    const std::string traj = (fs::path(a.out) / (c == 0 ? std::string("trajectory.cwtraj")
                                                         : "trajectory_" + Num(c) + ".cwtraj"))
                                 .string();
    sim::WriteTrajectory(traj, t);
    if (!a.no_obj) {
      sim::Mesh mesh;
      mesh.F = t.faces;
      mesh.U = t.uv.cast<double>();
      for (int f = 0; f < t.num_frames(); ++f) {
        mesh.V = t.frames[f].cast<double>();
        sim::WriteObj((fs::path(a.out) / FrameName(f, c)).string(), mesh);
      }
    }
    // Everything simulated, warm-up included (what the wall time paid for).
    const double simulated = t.steps * setup.cloths[c].options.dt;
    nlohmann::json s;
    s["cloth"] = c;
    s["vertices"] = t.num_vertices();
    s["faces"] = t.num_faces();
    s["frames"] = t.num_frames();
    s["steps"] = t.steps;
    s["time_step_s"] = setup.cloths[c].options.dt;
    s["max_edge_m"] = setup.cloths[c].max_edge;
    s["wall_seconds"] = t.wall_seconds;
    s["simulated_seconds"] = simulated;
    s["recorded_seconds"] = (t.num_frames() - 1) * t.frame_time;
    s["warmup_seconds"] = a.warmup;  // simulated before frame 0, not recorded
    s["wall_seconds_per_simulated_second"] = simulated > 0 ? t.wall_seconds / simulated : 0.0;
    s["times_real_time"] = t.wall_seconds > 0 ? simulated / t.wall_seconds : 0.0;
    s["trajectory"] = traj;
    nlohmann::json th;
    for (int i = 0; i < sim::kNumParameters; ++i) th[sim::ParameterNames()[i]] = theta[i];
    s["theta"] = th;
    summary["cloths"].push_back(s);
  }
  sim::WindSpec w = setup.wind;  // as simulated: speed from theta (cloth 0's)
  sim::ApplyTheta(theta0, nullptr, &w);
  summary["wind"] = {{"velocity", {w.velocity.x(), w.velocity.y(), w.velocity.z()}},
                     {"density", w.density},
                     {"drag", w.drag},
                     {"turbulence_intensity", w.turbulence.intensity},
                     {"turbulence_length_scale_m", w.turbulence.length_scale}};
  if (options.seed) summary["seed"] = *options.seed;
  summary["wall_seconds"] = total_wall;
  const std::string text = summary.dump(2) + "\n";
  sim::WriteFileAtomically((fs::path(a.out) / "summary.json").string(), text);
  std::cout << text;
  return 0;
}

const VerbRegistrar kRegistrar{"simulate", [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<SimulateArgs>();
  auto* sub = app.add_subcommand("simulate",
                                 "simulate an ArcSim scene: frame OBJs, binary trajectory, summary.json");
  // (A missing scene is an input refused, status 1, named by the reader, as every verb's missing input.)
  sub->add_option("scene", args->scene, "ArcSim scene JSON (comments allowed)")->required();
  sub->add_option("--out", args->out, "output folder")->required();
  auto* duration = sub->add_option("--duration", args->duration, "simulated seconds, > 0 (default: the scene's)");
  sub->add_option("--wind", args->wind, "mean wind VX,VY,VZ [m/s] (replaces the scene's)");
  sub->add_option("--turbulence", args->turbulence,
                  "turbulence intensity and length scale I,L [-, m]: I in 0..10, L in 0.01..10000 m");
  auto* seed = sub->add_option("--seed", args->seed, "seed of the wind's turbulence and gusts, >= 0");
  sub->add_option("--max-edge", args->max_edge,
                  "refine uniformly to this edge length [m] (default: the scene's: uniformly to the upper end of its "
                  "remeshing size range, then edges over 0.4 of it split)");
  sub->add_option("--frame-steps", args->frame_steps,
                  "time steps per frame, 0..10000 (0, the default: the scene's; fewer is faster but damps flapping)")
      ->check(CLI::Range(0, 10000));
  sub->add_option("--warmup", args->warmup,
                  "simulated seconds before the first written frame (the release transient), 0..3600 s in whole "
                  "frames [s]");
  sub->add_option("--param", args->params, "set a theta entry, NAME=VALUE (repeatable; e.g. area_weight=0.3)");
  sub->add_flag("--no-obj", args->no_obj, "skip the per-frame OBJ files");
  return [args, duration, seed] {
    args->duration_given = duration->count() > 0;
    args->seed_given = seed->count() > 0;
    return Run(*args);
  };
}};

}  // namespace
}  // namespace clothwind::tools
