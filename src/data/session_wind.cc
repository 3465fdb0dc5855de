#include "data/session_wind.h"

#include <cmath>
#include <stdexcept>

namespace clothwind::data {

SessionWindField::SessionWindField(std::shared_ptr<const sensors::SyntheticWind> wind,
                                   double direction_from, const sim::TurbulenceParams& turbulence,
                                   double mean_speed)
    : wind_(std::move(wind)), direction_from_(direction_from) {
  if (!wind_) throw std::invalid_argument("SessionWindField: no wind");
  if (turbulence.intensity > 0) {
    if (!(mean_speed > 0)) throw std::invalid_argument("SessionWindField: mean_speed must be > 0 m/s");
    turbulence_ = std::make_unique<sim::TurbulentWind>(turbulence, Eigen::Vector3d(mean_speed, 0, 0));
  }
}

Eigen::Vector3d SessionWindField::Direction(double t) const {
  double deviation = direction_from_ - wind_->FromAngle(t);  // [deg]
  deviation = std::remainder(deviation, 360.0);
  const double a = deviation * M_PI / 180.0;
  return Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
}

Eigen::Vector3d SessionWindField::Velocity(const Eigen::Vector3d& x, double t) const {
  Eigen::Vector3d v = wind_->Speed(t) * Direction(t);
  if (turbulence_) v += turbulence_->Velocity(x, t);
  return v;
}

}  // namespace clothwind::data
