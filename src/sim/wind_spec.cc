#include "sim/wind_spec.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/random.h"

namespace clothwind::sim {

void WindSpec::SetSeed(uint64_t seed) {
  turbulence.seed = DeriveSeed(seed, 0);
  gusts.seed = DeriveSeed(seed, 1);
}

std::shared_ptr<const WindField> MakeWindField(const WindSpec& spec) {
  // Checked here too: a SceneSetup's wind may be edited in code, past the scene reader's checks,
  // and a NaN or negative intensity or rate read as "none" (a steady wind, without a word).
  const auto require = [](bool ok, const std::string& field, const std::string& expected, double got) {
    if (!ok) throw std::invalid_argument("wind." + field + " must be " + expected + ", got " + std::to_string(got));
  };
  for (int i = 0; i < 3; ++i) require(std::isfinite(spec.velocity[i]), "velocity", "finite", spec.velocity[i]);
  require(spec.turbulence.intensity >= 0 && std::isfinite(spec.turbulence.intensity), "turbulence.intensity",
          "finite and >= 0", spec.turbulence.intensity);
  require(spec.gusts.rate >= 0 && std::isfinite(spec.gusts.rate), "gusts.rate", "finite and >= 0 [1/s]",
          spec.gusts.rate);
  require(std::isfinite(spec.gusts.amplitude), "gusts.amplitude", "finite [m/s]", spec.gusts.amplitude);
  // Gusts blow along the wind: a calm wind (a sample of speed 0) has no direction, and gusts of
  // full amplitude along +x made it anything but calm.
  const bool calm = spec.velocity.norm() == 0.0;
  const bool turbulent = spec.turbulence.intensity > 0.0 && !calm;
  const bool gusty = spec.gusts.rate > 0.0 && spec.gusts.amplitude != 0.0 && !calm;
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
