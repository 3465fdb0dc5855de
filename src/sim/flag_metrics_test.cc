#include "sim/flag_metrics.h"

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::sim {
namespace {

// A synthetic 3 x 2 m "flag" of 4 corner vertices + 2 edge midpoints, hoist on the z axis,
// drooping by a known angle and with its fly corner oscillating at a known frequency.
Trajectory SyntheticFlag(double droop_deg, double hz, double amp_lat, double amp_vert) {
  Trajectory t;
  t.frame_time = 0.04;
  t.uv.resize(6, 2);
  t.uv << 0, 0, 3, 0, 3, 2, 0, 2, 0, 1, 3, 1;
  t.faces.resize(4, 3);
  t.faces << 0, 1, 5, 0, 5, 4, 4, 5, 2, 4, 2, 3;
  const double a = droop_deg * M_PI / 180;
  for (int f = 0; f < 200; ++f) {
    const double time = f * t.frame_time;
    FramePositions p(6, 3);
    const Eigen::RowVector3f hoist_mid(0, 0, 1);
    const Eigen::RowVector3f fly_mid = hoist_mid + Eigen::RowVector3f(3 * std::cos(a), 0, -3 * std::sin(a));
    p.row(0) << 0, 0, 0;
    p.row(3) << 0, 0, 2;
    p.row(4) = hoist_mid;
    p.row(5) = fly_mid;
    p.row(1) = fly_mid - Eigen::RowVector3f(0, 0, 1);
    p.row(2) = fly_mid + Eigen::RowVector3f(0, amp_lat * std::sin(2 * M_PI * hz * time),
                                            1 + amp_vert * std::cos(2 * M_PI * hz * time));
    t.frames.push_back(p);
  }
  return t;
}

TEST(FlagMetrics, RecoversDroopFrequencyAndAmplitudeOfASyntheticFlag) {
  const Trajectory t = SyntheticFlag(30.0, 1.5, 0.3, 0.2);
  const FlagLandmarks l = FindFlagLandmarks(t.uv);
  EXPECT_EQ(l.hoist_mid, 4);
  EXPECT_EQ(l.fly_mid, 5);
  EXPECT_EQ(l.fly_upper, 2);
  // Wind along +x: lateral is y.
  const FlagMotion m = MeasureFlagMotion(t, Eigen::Vector3d::UnitX(), 0);
  EXPECT_NEAR(m.droop_deg, 30.0, 1e-4);
  EXPECT_NEAR(m.peak_hz, 1.5, 1e-9);  // 8 s window: 1.5 Hz is bin 12
  EXPECT_NEAR(m.dominant_hz, 1.5, 0.05);
  EXPECT_GT(m.peak_fraction, 0.4);
  EXPECT_NEAR(m.lateral_rms, 0.3 / std::sqrt(2.0), 0.01);
  EXPECT_NEAR(m.vertical_rms, 0.2 / std::sqrt(2.0), 0.01);
  // Wind along +y: the flag's "lateral" is then x, in which nothing moves.
  EXPECT_NEAR(MeasureFlagMotion(t, Eigen::Vector3d::UnitY(), 0).lateral_rms, 0.0, 1e-6);
  EXPECT_THROW(MeasureFlagMotion(t, Eigen::Vector3d::UnitX(), 198), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sim
