#include "sim/shear_wind.h"

#include <algorithm>
#include <cmath>

namespace clothwind::sim {

double ShearProfile::Factor(double z) const {
  const double h = z - ground_z;
  switch (kind) {
    case Kind::kNone:
      return 1.0;
    case Kind::kPower:
      return h <= 0.0 ? 0.0 : std::pow(h / reference_height, exponent);
    case Kind::kLog:
      return h <= roughness ? 0.0 : std::log(h / roughness) / std::log(reference_height / roughness);
  }
  return 1.0;
}

}  // namespace clothwind::sim
