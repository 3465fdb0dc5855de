#include "sim/wind_spec.h"

#include "common/random.h"

namespace clothwind::sim {

void WindSpec::SetSeed(uint64_t seed) {
  turbulence.seed = DeriveSeed(seed, 0);
  gusts.seed = DeriveSeed(seed, 1);
}

std::shared_ptr<const WindField> MakeWindField(const WindSpec& spec) {
  const bool turbulent = spec.turbulence.intensity > 0.0 && spec.velocity.norm() > 0.0;
  const bool gusty = spec.gusts.rate > 0.0 && spec.gusts.amplitude != 0.0;
  if (spec.shear.kind == ShearProfile::Kind::kNone && !turbulent && !gusty) {
    return std::make_shared<SteadyWind>(spec.velocity);
  }
  std::vector<std::shared_ptr<const WindField>> parts;
  if (spec.shear.kind == ShearProfile::Kind::kNone) {
    parts.push_back(std::make_shared<SteadyWind>(spec.velocity));
  } else {
    parts.push_back(std::make_shared<ShearWind>(spec.velocity, spec.shear));
  }
  if (turbulent) parts.push_back(std::make_shared<TurbulentWind>(spec.turbulence, spec.velocity));
  if (gusty) parts.push_back(std::make_shared<GustWind>(spec.gusts, spec.velocity));
  return std::make_shared<SumWind>(std::move(parts));
}

}  // namespace clothwind::sim
