// The flag of ArcSim's own flag.json in steady wind against what ArcSim does with it
// (/work/shared/reference/arcsim.md): the flag hangs at 1 m/s (~80 deg droop), lifts about
// halfway at 3 m/s (~52 deg), flies near horizontal at 10 m/s (~10 deg) and flaps there at
// ~1.5 Hz with a fly-corner RMS of 0.2-0.45 m. Tolerances are generous (ArcSim's own runs are
// short and carry start-up transients); the shape - droop falling steeply, frequency rising
// with wind - is what must hold.
//
// Resolution: the scene's default (every edge <= 0.2 m: 485 vertices; the uniformly refined
// 811-vertex mesh passes too). (The uniform 0.5 m mesh, 212 vertices, matched in some builds
// but not robustly: at 1 m/s its start-up swing had not died out after 8 s; docs/scenes.md.)
// 8 simulated seconds per wind, measured over the last 4 s
// (frequency resolution 0.25 Hz); the three winds run in parallel.
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include "sim/flag_metrics.h"
#include "sim/simulate.h"

namespace clothwind::sim {
namespace {

namespace fs = std::filesystem;

struct FlagRun {
  double max_edge;  // 0: the scene's default
  double wind;
  Trajectory trajectory;
};

TEST(FlagBehaviour, ArcSimFlagDroopsLessAndFlapsFasterAsWindRises) {
  const char* shared = std::getenv("CLOTHWIND_SHARED_DIR");
  const std::string path = std::string(shared ? shared : "") + "/arcsim/conf/flag.json";
  if (!shared || !fs::exists(path)) GTEST_SKIP() << "no " << path;
  const Scene scene = LoadScene(path);
  const std::vector<double> edges = {0.0};
  const std::vector<double> winds = {1.0, 3.0, 10.0};
  std::vector<SceneSetup> setups;
  for (double e : edges) setups.push_back(BuildScene(scene, BuildOptions{e}));
  std::vector<FlagRun> runs;
  for (double e : edges) {
    for (double w : winds) runs.push_back({e, w, {}});
  }
  // All at once, so both cores stay busy.
  tbb::parallel_for(size_t{0}, runs.size(), [&](size_t i) {
    const SceneSetup& setup = setups[i / winds.size()];
    Theta theta = SceneTheta(setup);
    theta[kWindSpeedIndex] = runs[i].wind;
    SimulateOptions options;
    options.duration = 8.0;
    runs[i].trajectory = SimulateTrajectory(setup, theta, options);
  });
  for (size_t r = 0; r < edges.size(); ++r) {
    SCOPED_TRACE("max edge " + std::to_string(edges[r]) + " m (0: default)");
    std::vector<FlagMotion> m;
    for (size_t i = 0; i < winds.size(); ++i) {
      const Trajectory& t = runs[r * winds.size() + i].trajectory;
      m.push_back(MeasureFlagMotion(t, Eigen::Vector3d::UnitX(), t.num_frames() / 2));
      std::cout << "wind " << winds[i] << " m/s, " << t.num_vertices() << " vertices: droop "
                << m[i].droop_deg << " deg, fly corner lateral RMS " << m[i].lateral_rms
                << " m, vertical RMS " << m[i].vertical_rms << " m, frequency " << m[i].dominant_hz
                << " Hz (peak " << m[i].peak_hz << " Hz), wall " << t.wall_seconds << " s\n";
    }
    // Droop: ~80 / 52-54 / 10-12 deg in ArcSim. The windows are as wide as can still tell a wind
    // load twice or half ArcSim's: with the scene's wind density doubled the flag droops 72.9 /
    // 40.7 / 4.9 deg, halved 75.5 deg at 3 m/s (review, stop 72); ours 78.7 / 52.0 / 9.6 (485
    // vertices). They were +-15 / +-15 / +-10, which passed a doubled load.
    EXPECT_NEAR(m[0].droop_deg, 80.0, 6.0);
    EXPECT_NEAR(m[1].droop_deg, 53.0, 7.0);
    EXPECT_NEAR(m[2].droop_deg, 11.0, 4.5);
    EXPECT_GT(m[0].droop_deg - m[1].droop_deg, 10.0);  // falls steeply with wind
    EXPECT_GT(m[1].droop_deg - m[2].droop_deg, 20.0);
    // Flapping at 10 m/s: ~1.5 Hz in ArcSim; accept 0.8-2.5 Hz. Frequency rises with wind.
    EXPECT_GT(m[2].dominant_hz, 0.8);
    EXPECT_LT(m[2].dominant_hz, 2.5);
    EXPECT_GT(m[2].dominant_hz, m[1].dominant_hz + 0.2);
    // ArcSim's table gives the dominant (strongest) frequency, ~1.4-1.6 Hz; dominant_hz above is a
    // power-weighted centroid. The strongest bin: ours 1.24 Hz at 485 vertices; 1.0-1.9 Hz.
    EXPECT_GT(m[2].peak_hz, 1.0);
    EXPECT_LT(m[2].peak_hz, 1.9);
    // Amplitude at 10 m/s: ArcSim 0.29-0.45 m lateral, 0.18-0.21 m vertical; accept a factor ~2.
    // (At 1 m/s the flag, released horizontal, still swings after 4 s: not asserted.)
    EXPECT_GT(m[2].lateral_rms, 0.12);
    EXPECT_LT(m[2].lateral_rms, 0.8);
    EXPECT_GT(m[2].vertical_rms, 0.08);
    EXPECT_LT(m[2].vertical_rms, 0.45);
  }
}

}  // namespace
}  // namespace clothwind::sim
