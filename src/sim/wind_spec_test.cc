#include "sim/wind_spec.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::sim {
namespace {

TEST(ShearProfile, PowerLawAndLogLaw) {
  ShearProfile p;
  p.kind = ShearProfile::Kind::kPower;
  p.exponent = 0.2;
  p.reference_height = 10.0;
  p.ground_z = -2.0;
  EXPECT_DOUBLE_EQ(p.Factor(8.0), 1.0);                      // h = 10 m = reference
  EXPECT_NEAR(p.Factor(18.0), std::pow(2.0, 0.2), 1e-12);    // h = 20 m
  EXPECT_NEAR(p.Factor(3.0), std::pow(0.5, 0.2), 1e-12);     // h = 5 m
  EXPECT_EQ(p.Factor(-2.0), 0.0);                            // at the ground
  p.kind = ShearProfile::Kind::kLog;
  p.roughness = 0.1;
  EXPECT_DOUBLE_EQ(p.Factor(8.0), 1.0);
  EXPECT_NEAR(p.Factor(18.0), std::log(200.0) / std::log(100.0), 1e-12);
  EXPECT_EQ(p.Factor(-1.95), 0.0);  // below z0
  // Monotone increasing with height.
  for (double z = -1.5; z < 30; z += 0.5) EXPECT_LT(p.Factor(z), p.Factor(z + 0.5));
}

TEST(MakeWindField, SteadyWhenNothingElseIsAsked) {
  WindSpec spec;
  spec.velocity = Eigen::Vector3d(3, 0, 0);
  const auto w = MakeWindField(spec);
  EXPECT_NE(dynamic_cast<const SteadyWind*>(w.get()), nullptr);
  EXPECT_EQ(w->Velocity(Eigen::Vector3d(1, 2, 3), 7.0), spec.velocity);
}

// A calm sample (wind speed 0) is calm: gusts blow along the wind, and without one they blew at
// full amplitude along +x.
TEST(MakeWindField, ACalmWindHasNoGustsOrTurbulence) {
  WindSpec spec;
  spec.turbulence.intensity = 0.2;
  spec.gusts.rate = 2.0;
  spec.gusts.amplitude = 3.0;
  spec.gusts.duration = 1.0;
  spec.SetSeed(5);
  const auto w = MakeWindField(spec);
  for (int i = 0; i < 200; ++i) EXPECT_EQ(w->Velocity(Eigen::Vector3d(0.1 * i, 0, 2), 0.05 * i).norm(), 0.0) << i;
}

// Checked where the field is made: an edited SceneSetup's NaN or negative intensity or rate read
// as "none" (a steady wind, without a word).
TEST(MakeWindField, BadParametersAreRefusedNamingTheField) {
  const auto error = [](WindSpec spec) {
    try {
      MakeWindField(spec);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  WindSpec spec;
  spec.velocity = Eigen::Vector3d(5, 0, 0);
  WindSpec bad = spec;
  bad.turbulence.intensity = NAN;
  EXPECT_NE(error(bad).find("wind.turbulence.intensity must be finite and >= 0"), std::string::npos) << error(bad);
  bad = spec;
  bad.turbulence.intensity = -0.1;
  EXPECT_NE(error(bad).find("wind.turbulence.intensity"), std::string::npos);
  bad = spec;
  bad.gusts.rate = -1;
  bad.gusts.amplitude = 2;
  EXPECT_NE(error(bad).find("wind.gusts.rate"), std::string::npos);
  bad = spec;
  bad.velocity.x() = INFINITY;
  EXPECT_NE(error(bad).find("wind.velocity must be finite"), std::string::npos);
  EXPECT_EQ(error(spec), "");
}

TEST(MakeWindField, ComposesShearTurbulenceAndGusts) {
  WindSpec spec;
  spec.velocity = Eigen::Vector3d(6, 0, 0);
  spec.shear.kind = ShearProfile::Kind::kPower;
  spec.shear.reference_height = 4.0;
  spec.turbulence.intensity = 0.1;
  spec.gusts.rate = 0.3;
  spec.gusts.amplitude = 2.0;
  spec.SetSeed(17);
  const auto w = MakeWindField(spec);
  const ShearWind shear(spec.velocity, spec.shear);
  const TurbulentWind turb(spec.turbulence, spec.velocity);
  const GustWind gusts(spec.gusts, spec.velocity);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d x(0.1 * i, 0.0, 0.2 * i + 0.5);
    const double t = 1.3 * i;
    const Eigen::Vector3d sum = shear.Velocity(x, t) + turb.Velocity(x, t) + gusts.Velocity(x, t);
    EXPECT_LT((w->Velocity(x, t) - sum).norm(), 1e-12);
  }
  // Time-averaged at the reference height the mean wind is recovered (turbulence zero-mean;
  // gusts add rate * duration * amplitude / 2 on average).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  const int n = 20000;
  for (int i = 0; i < n; ++i) mean += w->Velocity(Eigen::Vector3d(0, 0, 4.0), 0.1 * i) / n;
  const double gust_mean = spec.gusts.rate * spec.gusts.duration * spec.gusts.amplitude / 2;
  EXPECT_NEAR(mean.x(), 6.0 + gust_mean, 0.25);
  EXPECT_NEAR(mean.y(), 0.0, 0.15);
  EXPECT_NEAR(mean.z(), 0.0, 0.15);
}

TEST(WindSpec, SetSeedMakesReproducibleIndependentStreams) {
  WindSpec a, b;
  a.SetSeed(5);
  b.SetSeed(5);
  EXPECT_EQ(a.turbulence.seed, b.turbulence.seed);
  EXPECT_EQ(a.gusts.seed, b.gusts.seed);
  EXPECT_NE(a.turbulence.seed, a.gusts.seed);
  b.SetSeed(6);
  EXPECT_NE(a.turbulence.seed, b.turbulence.seed);
}

}  // namespace
}  // namespace clothwind::sim
