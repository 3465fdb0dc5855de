#include "sim/parameters.h"

#include <cmath>
#include <set>

#include <gtest/gtest.h>

namespace clothwind::sim {
namespace {

Material TestMaterial() {
  Eigen::Matrix<double, 6, 4> stretching;
  stretching.setConstant(50.0);
  Eigen::Matrix<double, 3, 5> bending;
  for (int d = 0; d < 3; ++d) {
    for (int c = 0; c < 5; ++c) bending(d, c) = 1e-5 * (1 + d + 0.1 * c);
  }
  MaterialMultipliers mult;
  mult.thicken = 2;
  return MakeMaterial(0.135, stretching, bending, mult);
}

TEST(Parameters, NamesAreUniqueAndIndexRoundTrips) {
  const auto& names = ParameterNames();
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), size_t{kNumParameters});
  EXPECT_EQ(names[0], "area_weight");
  EXPECT_EQ(names[16], "wind_speed");
  EXPECT_EQ(names[1 + 5 * 2 + 3], "bending_d2_c3");
  for (int i = 0; i < kNumParameters; ++i) EXPECT_EQ(ParameterIndex(names[i]), i);
  EXPECT_THROW(ParameterIndex("stiffness"), std::invalid_argument);
  EXPECT_EQ(ParameterUnits()[0], "kg/m^2");
}

TEST(Parameters, ThetaRoundTripsThroughMaterialAndWind) {
  const Material m = TestMaterial();
  WindSpec wind;
  wind.velocity = Eigen::Vector3d(3, 4, 0);  // 5 m/s
  const Theta theta = ThetaFrom(m, wind);
  EXPECT_DOUBLE_EQ(theta[0], 0.27);  // after thicken
  EXPECT_DOUBLE_EQ(theta[1 + 5 * 1 + 2], m.bending[1][2]);
  EXPECT_DOUBLE_EQ(theta[16], 5.0);

  Theta changed = theta;
  changed[0] = 0.4;
  changed[1 + 5 * 2 + 4] = 7e-5;
  changed[16] = 10.0;
  Material m2 = m;
  WindSpec w2 = wind;
  ApplyTheta(changed, &m2, &w2);
  EXPECT_DOUBLE_EQ(m2.density, 0.4);
  EXPECT_DOUBLE_EQ(m2.bending[2][4], 7e-5);
  EXPECT_DOUBLE_EQ(m2.bending[0][0], m.bending[0][0]);
  EXPECT_EQ(m2.stretching_samples, m.stretching_samples);  // untouched
  EXPECT_NEAR((w2.velocity - Eigen::Vector3d(6, 8, 0)).norm(), 0.0, 1e-12);  // same direction
  EXPECT_EQ(ThetaFrom(m2, w2), changed);
}

TEST(Parameters, ZeroWindTakesXAndBadValuesNameTheEntry) {
  Material m = TestMaterial();
  WindSpec still;
  Theta theta = ThetaFrom(m, still);
  theta[16] = 2.0;
  ApplyTheta(theta, &m, &still);
  EXPECT_EQ(still.velocity, Eigen::Vector3d(2, 0, 0));
  theta[5] = -1e-6;
  try {
    ApplyTheta(theta, &m, &still);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bending_d0_c4"), std::string::npos) << e.what();
  }
  theta[5] = 1e-6;
  theta[0] = std::nan("");
  EXPECT_THROW(ValidateTheta(theta), std::invalid_argument);
  // Past the material's cap (MakeMaterial refuses it; ApplyTheta wrote it).
  theta[0] = 2e3;
  try {
    ApplyTheta(theta, &m, &still);
    FAIL() << "an area weight of 2000 kg/m^2 was applied";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at most 1000"), std::string::npos) << e.what();
  }
  theta[0] = 0.1;
  theta[16] = -1;
  EXPECT_THROW(ValidateTheta(theta), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sim
