#include "sim/gust_wind.h"

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::sim {
namespace {

TEST(GustWind, OneMinusCosineShapePeaksMidwayWithItsAmplitude) {
  GustParams p;
  p.rate = 0.05;  // rare: gusts seldom overlap
  p.amplitude = 3.0;
  p.duration = 2.0;
  p.seed = 11;
  const GustWind w(p, Eigen::Vector3d(5, 0, 0));
  ASSERT_GE(w.gusts().size(), 50u);
  int checked = 0;
  for (size_t i = 0; i + 1 < w.gusts().size(); ++i) {
    const Gust& g = w.gusts()[i];
    if (i > 0 && g.start - w.gusts()[i - 1].start < p.duration) continue;
    if (w.gusts()[i + 1].start - g.start < p.duration) continue;
    EXPECT_NEAR(w.Speed(g.start + 0.5 * p.duration), g.amplitude, 1e-12);
    EXPECT_NEAR(w.Speed(g.start + 0.25 * p.duration), 0.5 * g.amplitude, 1e-12);
    // 0, 1/4 and 1/2 of the duration fit a triangle A (1 - |2 tau - 1|) too; at 1/8 and 7/8 the
    // 1 - cos shape gives A (1 - cos(pi/4)) / 2 ~ 0.146 A, the triangle 0.25 A.
    const double eighth = 0.5 * g.amplitude * (1 - std::cos(M_PI / 4));
    EXPECT_NEAR(w.Speed(g.start + 0.125 * p.duration), eighth, 1e-12);
    EXPECT_NEAR(w.Speed(g.start + 0.875 * p.duration), eighth, 1e-12);
    EXPECT_NEAR(w.Speed(g.start), 0.0, 1e-12);
    EXPECT_NEAR(w.Speed(g.start - 1e-3), 0.0, 1e-12);
    EXPECT_NEAR(w.Speed(g.start + p.duration + 1e-3), 0.0, 1e-12);
    EXPECT_GE(g.amplitude, p.amplitude * (1 - p.amplitude_spread));
    EXPECT_LE(g.amplitude, p.amplitude * (1 + p.amplitude_spread));
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

TEST(GustWind, ArrivalRateAndMeanAmplitudeMatchParameters) {
  GustParams p;
  p.rate = 0.2;
  p.amplitude = 2.0;
  p.horizon = 20000;  // ~4000 gusts
  p.seed = 5;
  const GustWind w(p, Eigen::Vector3d(3, 0, 0));
  const double n = w.gusts().size();
  // Poisson count: sd sqrt(4000) ~ 1.6%; tolerance 5%.
  EXPECT_NEAR(n / p.horizon, p.rate, 0.05 * p.rate);
  double mean_amp = 0, mean_gap = 0;
  for (const Gust& g : w.gusts()) mean_amp += g.amplitude / n;
  mean_gap = (w.gusts().back().start - w.gusts().front().start) / (n - 1);
  EXPECT_NEAR(mean_amp, p.amplitude, 0.03 * p.amplitude);
  EXPECT_NEAR(mean_gap, 1.0 / p.rate, 0.05 / p.rate);
  for (size_t i = 1; i < w.gusts().size(); ++i) {
    ASSERT_GE(w.gusts()[i].start, w.gusts()[i - 1].start);
  }
}

TEST(GustWind, SameSeedSameGustsAndFrontTravelsWithWind) {
  GustParams p;
  p.rate = 0.5;
  p.amplitude = 4.0;
  p.seed = 99;
  const Eigen::Vector3d mean(0, 8, 0);  // wind along +y
  const GustWind a(p, mean), b(p, mean);
  ASSERT_EQ(a.gusts().size(), b.gusts().size());
  for (size_t i = 0; i < a.gusts().size(); ++i) {
    EXPECT_EQ(a.gusts()[i].start, b.gusts()[i].start);
    EXPECT_EQ(a.gusts()[i].amplitude, b.gusts()[i].amplitude);
  }
  p.seed = 100;
  const GustWind c(p, mean);
  EXPECT_NE(a.gusts().front().start, c.gusts().front().start);
  // Along the wind direction, 4 m downstream the gust arrives 0.5 s later; velocity along +y.
  const Gust& g = a.gusts().front();
  const Eigen::Vector3d here(1, 0, 2), downstream(1, 4, 2);
  const double t = g.start + 0.3 * p.duration;
  EXPECT_NEAR((a.Velocity(here, t) - a.Velocity(downstream, t + 0.5)).norm(), 0.0, 1e-12);
  EXPECT_NEAR(a.Velocity(here, t).x(), 0.0, 1e-15);
  EXPECT_GT(a.Velocity(here, t).y(), 0.0);
}

TEST(GustWind, BadParametersThrowAndNoGustsIsStill) {
  GustParams p;
  EXPECT_EQ(GustWind(p, Eigen::Vector3d(1, 0, 0)).Velocity(Eigen::Vector3d::Zero(), 3.0),
            Eigen::Vector3d::Zero());
  p.rate = -1;
  EXPECT_THROW(GustWind(p, Eigen::Vector3d(1, 0, 0)), std::invalid_argument);
  p.rate = 1;
  p.duration = 0;
  EXPECT_THROW(GustWind(p, Eigen::Vector3d(1, 0, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sim
