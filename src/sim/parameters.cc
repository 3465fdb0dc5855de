#include "sim/parameters.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace clothwind::sim {

const std::array<std::string, kNumParameters>& ParameterNames() {
  static const std::array<std::string, kNumParameters> names = [] {
    std::array<std::string, kNumParameters> n;
    n[kAreaWeightIndex] = "area_weight";
    for (int d = 0; d < 3; ++d) {
      for (int c = 0; c < 5; ++c) {
        n[kBendingIndex + 5 * d + c] = "bending_d" + std::to_string(d) + "_c" + std::to_string(c);
      }
    }
    n[kWindSpeedIndex] = "wind_speed";
    return n;
  }();
  return names;
}

const std::array<std::string, kNumParameters>& ParameterUnits() {
  static const std::array<std::string, kNumParameters> units = [] {
    std::array<std::string, kNumParameters> u;
    u.fill("N m");
    u[kAreaWeightIndex] = "kg/m^2";
    u[kWindSpeedIndex] = "m/s";
    return u;
  }();
  return units;
}

int ParameterIndex(const std::string& name) {
  const auto& names = ParameterNames();
  for (int i = 0; i < kNumParameters; ++i) {
    if (names[i] == name) return i;
  }
  std::ostringstream msg;
  msg << "unknown parameter '" << name << "'; expected one of:";
  for (const auto& n : names) msg << " " << n;
  throw std::invalid_argument(msg.str());
}

Theta ThetaFrom(const Material& material, const WindSpec& wind) {
  Theta theta;
  theta[kAreaWeightIndex] = material.density;
  for (int d = 0; d < 3; ++d) {
    for (int c = 0; c < 5; ++c) theta[kBendingIndex + 5 * d + c] = material.bending[d][c];
  }
  theta[kWindSpeedIndex] = wind.velocity.stableNorm();  // norm() overflowed to inf for 1e200
  return theta;
}

void ValidateTheta(const Theta& theta) {
  const auto& names = ParameterNames();
  for (int i = 0; i < kNumParameters; ++i) {
    const double v = theta[i];
    const bool ok = std::isfinite(v) && (i == kWindSpeedIndex ? v >= 0.0 : v > 0.0) &&
                    (i != kAreaWeightIndex || v <= kMaxAreaWeight);
    if (!ok) {
      // The area weight's cap is the material's (MakeMaterial): ApplyTheta wrote past it.
      std::ostringstream msg;
      msg << "parameter " << i << " (" << names[i] << ") = " << v << " [" << ParameterUnits()[i]
          << "]: expected a finite number " << (i == kWindSpeedIndex ? ">= 0" : "> 0")
          << (i == kAreaWeightIndex ? " and at most 1000" : "");
      throw std::invalid_argument(msg.str());
    }
  }
}

void ApplyTheta(const Theta& theta, Material* material, WindSpec* wind) {
  ValidateTheta(theta);
  if (material) {
    material->density = theta[kAreaWeightIndex];
    for (int d = 0; d < 3; ++d) {
      for (int c = 0; c < 5; ++c) material->bending[d][c] = theta[kBendingIndex + 5 * d + c];
    }
  }
  if (wind) {
    const double speed = wind->velocity.norm();
    const Eigen::Vector3d dir = speed > 0 ? Eigen::Vector3d(wind->velocity / speed)
                                          : Eigen::Vector3d::UnitX();
    wind->velocity = theta[kWindSpeedIndex] * dir;
  }
}

}  // namespace clothwind::sim
