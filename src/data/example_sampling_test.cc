#include "data/example_sampling.h"

#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::data {
namespace {

sim::Theta BaseTheta() {
  sim::Theta t;
  t[0] = 0.27;
  for (int k = 1; k <= 15; ++k) t[k] = 3e-5 * k;
  t[16] = 3.0;
  return t;
}

// The documented derivations, written out here independently of common/random.h so that a
// change to the code under test (its stream constant, the mixing, the split's stream or draw)
// fails instead of being compared with itself: a dataset made from a seed today must get the
// seeds and splits it got a year ago.
//   SimulationSeed(g, i) = HashSeed(g, i, 0x5eedda7a)
//   SplitOf(s, val, test): u = the first Uniform() of Rng(HashSeed(s, 4)); test if u < test,
//                          val if u < test + val, else train
uint64_t ReferenceHashSeed(uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  uint64_t h = a * 0x9e3779b97f4a7c15ULL;
  for (uint64_t x : {b, c, d}) {
    h ^= x + 0x632be59bd9b4e019ULL + (h << 6) + (h >> 2);
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 31;
  }
  return h;
}

uint64_t ReferenceSimulationSeed(uint64_t global_seed, uint64_t index) {
  return ReferenceHashSeed(global_seed, index, 0x5eedda7aULL, 0);
}

std::string ReferenceSplit(uint64_t simulation_seed, double val_fraction, double test_fraction) {
  uint64_t z = ReferenceHashSeed(simulation_seed, 4, 0, 0) + 0x9e3779b97f4a7c15ULL;  // SplitMix64's first output
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  const double u = static_cast<double>(z >> 11) * 0x1.0p-53;
  return u < test_fraction ? "test" : u < test_fraction + val_fraction ? "val" : "train";
}

TEST(ExampleSamplingTest, SimulationSeedDependsOnGlobalSeedAndIndexOnly) {
  std::set<uint64_t> seen;
  for (uint64_t g = 0; g < 5; ++g)
    for (int64_t i = 0; i < 200; ++i) seen.insert(SimulationSeed(g, i));
  EXPECT_EQ(seen.size(), 1000u);  // no collisions across seeds and indices
  EXPECT_EQ(SimulationSeed(7, 12), SimulationSeed(7, 12));
  EXPECT_THROW(SimulationSeed(7, -1), std::invalid_argument);
  // Values of an independent big-integer implementation (Python, reduced mod 2^64) of the
  // formula above: every simulation's parameters, turbulence, split and views follow from these.
  EXPECT_EQ(SimulationSeed(0, 0), 17073249975117185832ULL);
  EXPECT_EQ(SimulationSeed(7, 12), 18113783181998945970ULL);
  EXPECT_EQ(SimulationSeed(5, 1234), 7222369404594022915ULL);
  EXPECT_EQ(SimulationSeed(UINT64_MAX, 999999), 7201227481990545264ULL);
  EXPECT_EQ(ReferenceSimulationSeed(7, 12), 18113783181998945970ULL);  // the reference agrees too
  for (uint64_t g : {0ULL, 1ULL, 42ULL, 0xffffffffffffULL})
    for (int64_t i = 0; i < 50; ++i)
      ASSERT_EQ(SimulationSeed(g, i), ReferenceSimulationSeed(g, static_cast<uint64_t>(i))) << g << " " << i;
}

TEST(ExampleSamplingTest, FlagDrawsStayInTheirRangesAndCoverThem) {
  const SamplingRanges r = DefaultRanges(render::SceneKind::kFlag);
  const sim::Theta base = BaseTheta();
  double wind_lo = 1e9, wind_hi = -1e9, aw_lo = 1e9, aw_hi = -1e9, bend_lo = 1e9, bend_hi = -1e9;
  for (int i = 0; i < 2000; ++i) {
    const SimulationSample s = SampleFlagSimulation(base, 3, i, r);
    EXPECT_EQ(s.index, i);
    EXPECT_EQ(s.seed, SimulationSeed(3, i));
    const double aw = s.theta[0] / base[0];
    EXPECT_GE(aw, 0.5 - 1e-12);
    EXPECT_LE(aw, 2.0 + 1e-12);
    for (int k = 1; k <= 15; ++k) {
      const double f = s.theta[k] / base[k];
      EXPECT_GE(f, 1.0 / (4 * 1.25) - 1e-12);
      EXPECT_LE(f, 4 * 1.25 + 1e-12);
      // One stiffness shared by the entries, each jittered by at most 1.25 either way: two
      // entries' factors are within 1.25^2 of each other (the jitter alone passed the range above).
      const double ratio = f / (s.theta[1] / base[1]);
      EXPECT_GE(ratio, 1.0 / (1.25 * 1.25) - 1e-12);
      EXPECT_LE(ratio, 1.25 * 1.25 + 1e-12);
      bend_lo = std::min(bend_lo, f);
      bend_hi = std::max(bend_hi, f);
    }
    EXPECT_GE(s.theta[16], 0.0);
    EXPECT_LT(s.theta[16], 10.0);
    // The flag's wind blows along +x with the sampled speed.
    EXPECT_DOUBLE_EQ(s.wind_velocity.x(), s.theta[16]);
    EXPECT_EQ(s.wind_velocity.y(), 0.0);
    wind_lo = std::min(wind_lo, s.theta[16]);
    wind_hi = std::max(wind_hi, s.theta[16]);
    aw_lo = std::min(aw_lo, aw);
    aw_hi = std::max(aw_hi, aw);
  }
  EXPECT_LT(wind_lo, 0.1);
  EXPECT_GT(wind_hi, 9.9);
  EXPECT_LT(aw_lo, 0.55);
  EXPECT_GT(aw_hi, 1.8);
  // The shared stiffness covers [1/4, 4] (a draw of 1 left only the jitter's 0.8-1.25).
  EXPECT_LT(bend_lo, 0.3);
  EXPECT_GT(bend_hi, 3.5);
  // Bending entries are not all scaled alike (the table's shape varies).
  const SimulationSample s = SampleFlagSimulation(base, 3, 0, r);
  EXPECT_GT(std::abs(s.theta[1] / base[1] - s.theta[2] / base[2]), 1e-6);
}

TEST(ExampleSamplingTest, NarrowAreaWeightSpreadKeepsTheWeightAndLeavesOtherDrawsAlone) {
  // A weighed flag (make-dataset --area-weight-spread 1.05): its weight stays within +-5 %, and
  // the same simulation index keeps its wind and bending draws (separate random streams).
  SamplingRanges weighed = DefaultRanges(render::SceneKind::kFlag);
  weighed.area_weight_factor = 1.05;
  const SamplingRanges wide = DefaultRanges(render::SceneKind::kFlag);
  const sim::Theta base = BaseTheta();
  double aw_lo = 1e9, aw_hi = -1e9;
  for (int i = 0; i < 500; ++i) {
    const SimulationSample a = SampleFlagSimulation(base, 5, i, weighed);
    const SimulationSample b = SampleFlagSimulation(base, 5, i, wide);
    const double aw = a.theta[0] / base[0];
    aw_lo = std::min(aw_lo, aw);
    aw_hi = std::max(aw_hi, aw);
    EXPECT_EQ(a.theta[16], b.theta[16]) << "wind of simulation " << i;
    // Bending draws come after the weight's in the same stream: the same values.
    for (int k = 1; k <= 15; ++k) EXPECT_EQ(a.theta[k], b.theta[k]) << "bending " << k << " of simulation " << i;
  }
  EXPECT_GE(aw_lo, 1 / 1.05 - 1e-12);
  EXPECT_LE(aw_hi, 1.05 + 1e-12);
  EXPECT_LT(aw_lo, 0.96);
  EXPECT_GT(aw_hi, 1.04);
  // No spread at all: the scene's weight, and still the same bending draws.
  weighed.area_weight_factor = 1.0;
  const SimulationSample fixed = SampleFlagSimulation(base, 5, 3, weighed);
  EXPECT_EQ(fixed.theta[0], base[0]);
  EXPECT_EQ(fixed.theta[1], SampleFlagSimulation(base, 5, 3, wide).theta[1]);
}

TEST(ExampleSamplingTest, ClothDrawsFabricAreaWeightAndHorizontalWind) {
  std::vector<Fabric> fabrics(3);
  for (int f = 0; f < 3; ++f) {
    fabrics[f].name = "fabric" + std::to_string(f);
    for (int d = 0; d < 3; ++d)
      for (int c = 0; c < 5; ++c) fabrics[f].material.bending[d][c] = 1e-5 * (f + 1) * (d + c + 1);
  }
  const SamplingRanges r = DefaultRanges(render::SceneKind::kCloth);
  std::set<int> used;
  double speed_min = 5, speed_max = 0;
  for (int i = 0; i < 500; ++i) {
    const SimulationSample s = SampleClothSimulation(fabrics, 11, i, r);
    used.insert(s.fabric_index);
    EXPECT_EQ(s.fabric, fabrics[s.fabric_index].name);
    EXPECT_GE(s.theta[0], 0.1);
    EXPECT_LE(s.theta[0], 0.4);
    EXPECT_DOUBLE_EQ(s.theta[1 + 5 * 2 + 3], fabrics[s.fabric_index].material.bending[2][3]);
    EXPECT_EQ(s.wind_velocity.z(), 0.0);
    EXPECT_NEAR(s.wind_velocity.norm(), s.theta[16], 1e-12);
    EXPECT_LE(s.theta[16], 5.0);
    // One direction, the paper's [s, s, 0]: away from the camera on -x, 45° to the cloth's normal.
    if (s.theta[16] > 0) {
      EXPECT_NEAR(s.wind_velocity.x(), s.wind_velocity.y(), 1e-12);
      EXPECT_GT(s.wind_velocity.x(), 0);
    }
    speed_min = std::min(speed_min, s.theta[16]);
    speed_max = std::max(speed_max, s.theta[16]);
  }
  EXPECT_EQ(used.size(), 3u);
  EXPECT_LT(speed_min, 0.1);  // speeds cover the range
  EXPECT_GT(speed_max, 4.9);
  EXPECT_THROW(SampleClothSimulation({}, 1, 0, r), std::invalid_argument);
}

TEST(ExampleSamplingTest, ViewsShareTheSceneAndSpreadTheCameraAngle) {
  const uint64_t seed = SimulationSeed(1, 4);
  const int views = 3;
  const render::RenderParams v0 = SampleView(render::SceneKind::kFlag, seed, 0, views);
  for (int v = 0; v < views; ++v) {
    const render::RenderParams p = SampleView(render::SceneKind::kFlag, seed, v, views);
    EXPECT_EQ(p.texture_name, v0.texture_name);
    EXPECT_EQ(p.texture_seed, v0.texture_seed);
    EXPECT_EQ(p.sun_azimuth_deg, v0.sun_azimuth_deg);
    EXPECT_EQ(p.background_seed, v0.background_seed);
    // Stratified angle: view v of 3 in [-15 + 10 v, -5 + 10 v).
    EXPECT_GE(p.camera_angle_deg, -15.0 + 10.0 * v);
    EXPECT_LT(p.camera_angle_deg, -5.0 + 10.0 * v);
    EXPECT_GE(p.camera_radius, 4.0);
    EXPECT_LT(p.camera_radius, 6.0);
    EXPECT_NO_THROW(render::ValidateRenderParams(p));
    if (v > 0) {
      EXPECT_NE(p.seed, v0.seed);
    }
  }
  const render::RenderParams c = SampleView(render::SceneKind::kCloth, seed, 1, 2);
  EXPECT_GE(c.camera_angle_deg, 0.0);
  EXPECT_LT(c.camera_angle_deg, 5.0);
  EXPECT_EQ(c.texture_kind, "fabric");
  EXPECT_THROW(SampleView(render::SceneKind::kFlag, seed, 3, 3), std::invalid_argument);
}

TEST(ExampleSamplingTest, OtherCamerasSeeTheSameScene) {
  // Two datasets of one seed that differ only in their camera ranges show the same scenes: the
  // controlled comparison docs/sdn-experiments.md makes between Table 2's cameras and level ones.
  const uint64_t seed = SimulationSeed(1, 9);
  const int views = 4;
  render::CameraRanges level;
  level.height_min = 5.1, level.height_max = 6.1;
  level.angle_max_deg = 8;
  for (int v = 0; v < views; ++v) {
    const render::RenderParams table = SampleView(render::SceneKind::kFlag, seed, v, views);
    render::RenderParams p = SampleView(render::SceneKind::kFlag, seed, v, views, {}, level);
    EXPECT_GE(p.camera_height, 5.1);
    EXPECT_LE(p.camera_height, 6.1);
    EXPECT_GE(p.camera_angle_deg, -8.0 + 4.0 * v);  // stratified over [-8, 8]
    EXPECT_LT(p.camera_angle_deg, -4.0 + 4.0 * v);
    EXPECT_DOUBLE_EQ(p.camera_radius, table.camera_radius);  // radius range unchanged
    p.camera_height = table.camera_height;
    p.camera_angle_deg = table.camera_angle_deg;
    EXPECT_EQ(render::ToJson(p), render::ToJson(table));
  }
  SamplingRanges r = DefaultRanges(render::SceneKind::kFlag);
  EXPECT_TRUE(r.camera == render::TableTwoCameraRanges(render::SceneKind::kFlag));
  EXPECT_TRUE(DefaultRanges(render::SceneKind::kCloth).camera ==
              render::TableTwoCameraRanges(render::SceneKind::kCloth));
  r.camera.height_max = 0.1;  // below its min
  EXPECT_THROW(SampleFlagSimulation(sim::Theta::Zero(), 1, 0, r), std::invalid_argument);
}

TEST(ExampleSamplingTest, SplitsFollowTheFractions) {
  int counts[3] = {0, 0, 0};
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const std::string s = SplitOf(SimulationSeed(5, i), 0.1, 0.2);
    counts[s == "train" ? 0 : s == "val" ? 1 : 2]++;
    EXPECT_EQ(s, SplitOf(SimulationSeed(5, i), 0.1, 0.2));
  }
  EXPECT_NEAR(counts[0] / double(n), 0.7, 0.015);
  EXPECT_NEAR(counts[1] / double(n), 0.1, 0.01);
  EXPECT_NEAR(counts[2] / double(n), 0.2, 0.012);
  EXPECT_THROW(SplitOf(1, 0.6, 0.6), std::invalid_argument);
  // The splits of dataset seed 5's first simulations, from the independent Python implementation
  // (index 8 draws u = 0.2001, just past the test fraction): a dataset regenerated or resumed
  // must put each simulation in the split it was in.
  const std::vector<std::string> expected = {"train", "train", "train", "train", "train", "train",
                                             "test",  "test",  "val",   "test",  "test",  "train",
                                             "train", "train", "train", "train", "train", "train",
                                             "test",  "train", "train", "test",  "train", "test"};
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(SplitOf(SimulationSeed(5, i), 0.1, 0.2), expected[i]) << i;
  for (int i = 0; i < 500; ++i) {
    const uint64_t seed = ReferenceSimulationSeed(5, i);
    ASSERT_EQ(SplitOf(seed, 0.1, 0.2), ReferenceSplit(seed, 0.1, 0.2)) << i;
    ASSERT_EQ(SplitOf(seed, 0.3, 0.05), ReferenceSplit(seed, 0.3, 0.05)) << i;
  }
}

// Cameras so far that the cloth is a few pixels, or so near it overflows the frame, are said
// (clips without a visible flag went into a dataset without a word); Table 2's are not, at any
// frame size.
TEST(ExampleSamplingTest, CameraRangesThatShowLittleOfTheClothWarn) {
  const render::CameraRanges flag = DefaultRanges(render::SceneKind::kFlag).camera;
  for (int px : {16, 64, 300}) {
    EXPECT_TRUE(CameraRangeWarnings(flag, 3.0, 5.6, px).empty()) << px;
    EXPECT_TRUE(CameraRangeWarnings(DefaultRanges(render::SceneKind::kCloth).camera, 1.0, 2.5, px).empty()) << px;
  }
  render::CameraRanges far = flag;
  far.radius_min = 900;
  far.radius_max = 1000;
  // 1000 m away and 5.4 m below the centre: the frame spans 2 x 1000.01 x tan(22.5 deg) = 828.4 m,
  // the 3 m flag 300 x 3 / 828.4 = 1.09 px.
  const std::vector<std::string> w = CameraRangeWarnings(far, 3.0, 5.6, 300);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NE(w[0].find("up to 1000 m away (--camera-radius, --camera-height)"), std::string::npos) << w[0];
  EXPECT_NE(w[0].find("about 1.09 px of the 300 px frame"), std::string::npos) << w[0];
  // Far by height alone: 90-100 m up at Table 2's radii, 94.6 m from the centre: 11.5 px of 300.
  render::CameraRanges high = flag;
  high.height_min = 90;
  high.height_max = 100;
  const std::vector<std::string> h = CameraRangeWarnings(high, 3.0, 5.6, 300);
  ASSERT_EQ(h.size(), 1u);
  EXPECT_NE(h[0].find("up to 94.59 m away"), std::string::npos) << h[0];
  EXPECT_NE(h[0].find("about 11.5 px"), std::string::npos) << h[0];
  render::CameraRanges near = flag;
  near.radius_min = 1.0;  // within half the 3 m flag's length of its centre
  const std::vector<std::string> n = CameraRangeWarnings(near, 3.0, 5.6, 300);
  ASSERT_EQ(n.size(), 1u);
  EXPECT_NE(n[0].find("from 1 m from the cloth's centre"), std::string::npos) << n[0];
  EXPECT_NE(n[0].find("it overflows the frame"), std::string::npos) << n[0];
  EXPECT_TRUE(CameraRangeWarnings(near, 0.0, 5.6, 300).empty());  // size unknown: nothing said
}

TEST(ExampleSamplingTest, ExampleNames) {
  EXPECT_EQ(ExampleName(render::SceneKind::kFlag, 12, 1), "flag-000012-v1");
  EXPECT_EQ(ExampleName(render::SceneKind::kCloth, 1234567, 0), "cloth-1234567-v0");
}

}  // namespace
}  // namespace clothwind::data
