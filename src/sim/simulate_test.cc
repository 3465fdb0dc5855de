#include "sim/simulate.h"

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace clothwind::sim {
namespace {

std::string SourceDir() {
  const char* s = std::getenv("CLOTHWIND_SOURCE_DIR");
  return s ? s : ".";
}

// Our flag scene, unrefined (63 vertices) and with turbulence and gusts, so seeds matter.
SceneSetup SmallFlag() {
  BuildOptions b;
  b.max_edge = 0.6;  // the generated mesh's longest edge is 0.5 m: no refinement
  SceneSetup s = BuildScene(LoadScene(SourceDir() + "/config/scenes/flag.json"), b);
  s.wind.turbulence.intensity = 0.2;
  s.wind.turbulence.length_scale = 5.0;
  s.wind.gusts.rate = 2.0;
  s.wind.gusts.amplitude = 2.0;
  s.wind.gusts.duration = 0.3;
  return s;
}

bool Identical(const Trajectory& a, const Trajectory& b) {
  if (a.num_frames() != b.num_frames() || a.faces != b.faces || a.uv != b.uv) return false;
  for (int f = 0; f < a.num_frames(); ++f) {
    if (a.frames[f] != b.frames[f]) return false;
  }
  return true;
}

TEST(SimulateTrajectory, FramesStepsAndShapes) {
  const SceneSetup setup = SmallFlag();
  SimulateOptions o;
  o.duration = 0.4;
  o.seed = 1;
  int calls = 0;
  o.progress = [&](int done, int total) {
    EXPECT_EQ(done, ++calls);
    EXPECT_EQ(total, 10);
    return true;
  };
  const Trajectory t = SimulateTrajectory(setup, SceneTheta(setup), o);
  EXPECT_EQ(calls, 10);
  EXPECT_EQ(t.num_frames(), 11);  // frame 0 + 0.4 s / 0.04 s
  EXPECT_EQ(t.steps, 80);         // 8 steps per frame
  EXPECT_EQ(t.num_vertices(), setup.cloths[0].mesh.V.rows());
  EXPECT_EQ(t.faces, setup.cloths[0].mesh.F);
  EXPECT_EQ(t.frames[0], setup.cloths[0].mesh.V.cast<float>());
  EXPECT_DOUBLE_EQ(t.frame_time, 0.04);
  EXPECT_GT(t.wall_seconds, 0.0);
  // The cloth moved (gravity and wind), the handles did not.
  EXPECT_GT((t.frames.back() - t.frames.front()).norm(), 0.05);
  for (int h : setup.cloths[0].options.handles) {
    EXPECT_EQ(t.frames.back().row(h), t.frames.front().row(h));
  }
}

TEST(SimulateTrajectory, CountsTheStrainLimitersSweepsAndUnconvergedSteps) {
  // The flag scene limits stretches to 0.95-1.05. One sweep a step: exactly one sweep counted
  // per step, and a flag falling and blown out is not within 0.1 % of its limits after one
  // sweep in every step. With the limits off nothing is counted.
  SceneSetup setup = SmallFlag();
  SimulateOptions o;
  o.duration = 0.4;
  o.seed = 1;
  setup.cloths[0].options.strain_limit_iterations = 1;
  const Trajectory one = SimulateTrajectory(setup, SceneTheta(setup), o);
  EXPECT_EQ(one.strain_limit_sweeps, one.steps);
  EXPECT_GT(one.strain_limit_unconverged, 0);
  EXPECT_LE(one.strain_limit_unconverged, one.steps);
  setup.cloths[0].options.strain_limit_iterations = 3;
  const Trajectory three = SimulateTrajectory(setup, SceneTheta(setup), o);
  EXPECT_GT(three.strain_limit_sweeps, three.steps);
  EXPECT_LE(three.strain_limit_sweeps, 3 * three.steps);
  setup.cloths[0].options.strain_max = std::numeric_limits<double>::infinity();
  setup.cloths[0].options.strain_min = 0;
  const Trajectory none = SimulateTrajectory(setup, SceneTheta(setup), o);
  EXPECT_EQ(none.strain_limit_sweeps, 0);
  EXPECT_EQ(none.strain_limit_unconverged, 0);
}

TEST(SimulateTrajectory, WarmupDropsLeadingFramesOfTheSameRun) {
  const SceneSetup setup = SmallFlag();
  SimulateOptions o;
  o.seed = 2;
  o.duration = 0.4;
  const Trajectory full = SimulateTrajectory(setup, SceneTheta(setup), o);
  o.duration = 0.24;
  o.warmup = 0.16;  // 4 frames
  int last_done = 0, last_total = 0;
  o.progress = [&](int done, int total) {
    last_done = done, last_total = total;
    return true;
  };
  const Trajectory warm = SimulateTrajectory(setup, SceneTheta(setup), o);
  EXPECT_EQ(last_done, 10);
  EXPECT_EQ(last_total, 10);
  ASSERT_EQ(warm.num_frames(), 7);
  EXPECT_EQ(warm.steps, full.steps);
  for (int f = 0; f < warm.num_frames(); ++f) EXPECT_EQ(warm.frames[f], full.frames[f + 4]) << f;
  // Negative, NaN and beyond an hour are refused (1e8 s overflowed the frame count: no warm-up).
  for (double bad : {-1.0, std::nan(""), 1e8}) {
    o.warmup = bad;
    EXPECT_THROW(SimulateTrajectory(setup, SceneTheta(setup), o), std::invalid_argument) << bad;
  }
}

// ArcSim's cloths[i].velocity starts the cloth moving. Without gravity, air or handles a cloth at
// its rest shape feels no force, so every node keeps its initial velocity: x(t) = x(0) + v t
// (momentum conservation, the free-flight invariant). Pinned nodes start still whatever the scene
// says. (The velocity was read and dropped with a warning before 2026-12-07.)
TEST(SimulateTrajectory, TheScenesInitialVelocityMovesAFreeClothRigidly) {
  BuildOptions b;
  b.max_edge = 0.6;
  Scene scene = LoadScene(SourceDir() + "/config/scenes/flag.json");
  scene.gravity.setZero();
  scene.wind = WindSpec{};
  scene.wind.density = 0;  // no air: no drag on the moving cloth
  const Eigen::Vector3d v(1.5, -2.0, 0.5);
  scene.cloths[0].velocity.linear = v;
  const std::vector<SceneHandle> handles = scene.handles;
  scene.handles.clear();
  const SceneSetup free = BuildScene(scene, b);
  SimulateOptions o;
  o.duration = 0.4;
  const Trajectory t = SimulateTrajectory(free, SceneTheta(free), o);
  ASSERT_EQ(t.num_frames(), 11);
  for (int f = 0; f < t.num_frames(); ++f) {
    const Eigen::MatrixX3d expected = (free.cloths[0].mesh.V.rowwise() + (v * f * t.frame_time).transpose());
    EXPECT_LT((t.frames[f].cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-4) << "frame " << f;
  }
  // With the flag's handles back, the hoist stays where it is and the rest moves off.
  scene.handles = handles;
  const SceneSetup held = BuildScene(scene, b);
  const Trajectory h = SimulateTrajectory(held, SceneTheta(held), o);
  const std::vector<int>& pinned = held.cloths[0].options.handles;
  ASSERT_FALSE(pinned.empty());
  for (int n : pinned) EXPECT_EQ(h.frames[1].row(n), h.frames[0].row(n)) << "pinned node " << n;
  int moved = 0;
  for (Eigen::Index n = 0; n < h.frames[1].rows(); ++n) moved += (h.frames[1].row(n) - h.frames[0].row(n)).norm() > 0.01;
  EXPECT_GT(moved, h.frames[1].rows() / 2);
}

// The scene reader's limits hold for a duration given in code: inf went to lround (undefined),
// 1e9 s overflowed the frame count, NaN ran the scene's duration.
TEST(SimulateTrajectory, ADurationPastTheScenesLimitsIsRefused) {
  const SceneSetup setup = SmallFlag();
  for (double bad : {std::numeric_limits<double>::infinity(), 1e9, 86401.0, std::numeric_limits<double>::quiet_NaN()}) {
    SimulateOptions o;
    o.duration = bad;
    try {
      SimulateTrajectory(setup, SceneTheta(setup), o);
      ADD_FAILURE() << bad << " s ran";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("duration must be at most 86400 s"), std::string::npos) << e.what();
    }
  }
}

TEST(SimulateTrajectory, ProgressCanStopEarly) {
  const SceneSetup setup = SmallFlag();
  SimulateOptions o;
  o.duration = 1.0;
  o.progress = [](int done, int) { return done < 3; };
  EXPECT_EQ(SimulateTrajectory(setup, SceneTheta(setup), o).num_frames(), 4);
}

TEST(SimulateTrajectory, DeterministicAcrossRunsAndThreadsAndSeedsMatter) {
  const SceneSetup setup = SmallFlag();
  const Theta theta = SceneTheta(setup);
  SimulateOptions o;
  o.duration = 0.4;
  o.seed = 7;
  const Trajectory a = SimulateTrajectory(setup, theta, o);
  const Trajectory b = SimulateTrajectory(setup, theta, o);
  EXPECT_TRUE(Identical(a, b));
  // Two other threads at once, sharing the setup.
  Trajectory c, d;
  std::thread t1([&] { c = SimulateTrajectory(setup, theta, o); });
  std::thread t2([&] { d = SimulateTrajectory(setup, theta, o); });
  t1.join();
  t2.join();
  EXPECT_TRUE(Identical(a, c));
  EXPECT_TRUE(Identical(a, d));
  o.seed = 8;
  EXPECT_FALSE(Identical(a, SimulateTrajectory(setup, theta, o)));
}

TEST(SimulateTrajectory, WindHookReceivesThetasWindAndItsFieldIsUsed) {
  const SceneSetup setup = SmallFlag();
  Theta theta = SceneTheta(setup);
  theta[kWindSpeedIndex] = 7.0;
  SimulateOptions o;
  o.duration = 0.2;
  Eigen::Vector3d seen = Eigen::Vector3d::Zero();
  o.make_wind = [&](const WindSpec& spec) -> std::shared_ptr<const WindField> {
    seen = spec.velocity;
    return std::make_shared<SteadyWind>(Eigen::Vector3d::Zero());  // still air instead
  };
  const Trajectory hooked = SimulateTrajectory(setup, theta, o);
  EXPECT_NEAR((seen - Eigen::Vector3d(7, 0, 0)).norm(), 0.0, 1e-12);
  // The hook's still air was used: same as a scene without wind and gusts, unlike 7 m/s.
  o.make_wind = nullptr;
  EXPECT_FALSE(Identical(hooked, SimulateTrajectory(setup, theta, o)));
  SceneSetup still = setup;
  still.wind.gusts.rate = 0.0;
  theta[kWindSpeedIndex] = 0.0;
  EXPECT_TRUE(Identical(hooked, SimulateTrajectory(still, theta, o)));
}

TEST(SimulateTrajectory, GustsLastTheWholeRunUnlessTheSceneSetsTheirHorizon) {
  // An hour's default horizon ended the gusts of longer runs (a day-long scene, or an hour's
  // warm-up). The hook sees the spec the run's field is made from; it stops the run there.
  const SceneSetup setup = SmallFlag();
  SimulateOptions o;
  o.duration = 600.0;
  o.warmup = 3600.0;
  double horizon = 0;
  o.make_wind = [&](const WindSpec& spec) -> std::shared_ptr<const WindField> {
    horizon = spec.gusts.horizon;
    throw std::runtime_error("seen");
  };
  EXPECT_THROW(SimulateTrajectory(setup, SceneTheta(setup), o), std::runtime_error);
  EXPECT_GE(horizon, 4200.0);
  SceneSetup given = setup;
  given.wind.gusts.horizon = 100.0;
  given.wind.gusts.horizon_given = true;
  EXPECT_THROW(SimulateTrajectory(given, SceneTheta(given), o), std::runtime_error);
  EXPECT_EQ(horizon, 100.0);
}

TEST(SimulateTrajectory, HangingClothIsBlownDownwindAndLiftedByItsDiagonalWind) {
  BuildOptions b;
  b.max_edge = 0.3;
  const SceneSetup setup = BuildScene(LoadScene(SourceDir() + "/config/scenes/cloth.json"), b);
  SimulateOptions o;
  o.duration = 0.4;
  Theta theta = SceneTheta(setup);
  theta[kWindSpeedIndex] = 4.0;  // along (1, 1, 0)/sqrt(2)
  const Trajectory t = SimulateTrajectory(setup, theta, o);
  const FramePositions& first = t.frames.front();
  const FramePositions& last = t.frames.back();
  for (int h : setup.cloths[0].options.handles) EXPECT_EQ(last.row(h), first.row(h));
  // The cloth hangs in the y-z plane (top corners 2, 3 at z = 1); the wind's x component blows
  // its free bottom corners (0, 1) downwind (+x) and lifts them. In still air they stay put.
  theta[kWindSpeedIndex] = 0.0;
  const Trajectory calm = SimulateTrajectory(setup, theta, o);
  for (int corner : {0, 1}) {
    const Eigen::Vector3f moved = (last.row(corner) - first.row(corner)).transpose();
    EXPECT_GT(moved.x(), 0.1) << corner;
    EXPECT_GT(moved.z(), 0.05) << corner;
    EXPECT_LT((calm.frames.back().row(corner) - first.row(corner)).norm(), 0.02) << corner;
  }
}

TEST(SimulateTrajectories, BatchMatchesSerialRunsInOrder) {
  const SceneSetup setup = SmallFlag();
  std::vector<Theta> thetas;
  for (double w : {2.0, 5.0, 8.0}) {
    Theta theta = SceneTheta(setup);
    theta[kWindSpeedIndex] = w;
    theta[kAreaWeightIndex] *= 1 + 0.1 * w;
    thetas.push_back(theta);
  }
  SimulateOptions o;
  o.duration = 0.2;
  std::atomic<int> reported{0};
  o.progress = [&](int, int total) {
    EXPECT_EQ(total, 3);
    ++reported;
    return true;
  };
  const std::vector<uint64_t> seeds = {1, 2, 3};
  const auto batch = SimulateTrajectories(setup, thetas, o, seeds);
  EXPECT_EQ(reported.load(), 3);
  ASSERT_EQ(batch.size(), 3u);
  for (size_t i = 0; i < thetas.size(); ++i) {
    SimulateOptions one;
    one.duration = 0.2;
    one.seed = seeds[i];
    EXPECT_TRUE(Identical(batch[i], SimulateTrajectory(setup, thetas[i], one))) << i;
  }
  EXPECT_FALSE(Identical(batch[0], batch[2]));
  EXPECT_THROW(SimulateTrajectories(setup, thetas, o, {1}), std::invalid_argument);
}

TEST(SimulateTrajectory, ThetaChangesTheMotionAndBadThetaThrows) {
  const SceneSetup setup = SmallFlag();
  SimulateOptions o;
  o.duration = 0.3;
  o.seed = 3;
  const Theta theta = SceneTheta(setup);
  Theta heavy = theta;
  heavy[kAreaWeightIndex] *= 3;
  // The same wind pushes a heavier flag less far downwind (+x) in the same time.
  const auto mean_x = [](const Trajectory& t) { return t.frames.back().col(0).mean(); };
  EXPECT_GT(mean_x(SimulateTrajectory(setup, theta, o)), mean_x(SimulateTrajectory(setup, heavy, o)));
  Theta bad = theta;
  bad[kWindSpeedIndex] = -1;
  EXPECT_THROW(SimulateTrajectory(setup, bad, o), std::invalid_argument);
  o.cloth = 1;
  EXPECT_THROW(SimulateTrajectory(setup, theta, o), std::out_of_range);
}

}  // namespace
}  // namespace clothwind::sim
