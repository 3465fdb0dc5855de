#include "sim/gust_wind.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/random.h"

namespace clothwind::sim {

GustWind::GustWind(const GustParams& p, const Eigen::Vector3d& mean_velocity)
    : params_(p),
      direction_(mean_velocity.norm() > 1e-9 ? mean_velocity.normalized()
                                             : Eigen::Vector3d::UnitX()),
      front_speed_(mean_velocity.norm()) {
  if (!std::isfinite(p.rate) || p.rate < 0.0) throw std::invalid_argument("gust rate must be >= 0 [1/s]");
  if (!(p.duration > 0.0) || !std::isfinite(p.duration)) {
    throw std::invalid_argument("gust duration must be > 0 [s]");
  }
  if (!std::isfinite(p.amplitude) || !std::isfinite(p.amplitude_spread) ||
      p.amplitude_spread < 0.0 || p.amplitude_spread > 1.0) {
    throw std::invalid_argument("gust amplitude must be finite, spread in [0, 1]");
  }
  if (p.rate == 0.0 || p.amplitude == 0.0) return;
  Rng g(p.seed);
  double t = 0.0;
  while (true) {
    t += -std::log(1.0 - g.Uniform()) / p.rate;  // exponential inter-arrival
    if (t >= p.horizon) break;
    const double a = p.amplitude * g.Uniform(1.0 - p.amplitude_spread, 1.0 + p.amplitude_spread);
    gusts_.push_back({t, a});
  }
}

double GustWind::Speed(double t) const {
  // Gusts that started within the last `duration` seconds.
  auto it = std::upper_bound(gusts_.begin(), gusts_.end(), t,
                             [](double v, const Gust& g) { return v < g.start; });
  double s = 0.0;
  while (it != gusts_.begin()) {
    --it;
    const double phase = (t - it->start) / params_.duration;
    if (phase > 1.0) break;
    s += 0.5 * it->amplitude * (1.0 - std::cos(2.0 * M_PI * phase));
  }
  return s;
}

Eigen::Vector3d GustWind::Velocity(const Eigen::Vector3d& x, double t) const {
  const double delay = front_speed_ > 1e-9 ? x.dot(direction_) / front_speed_ : 0.0;
  return Speed(t - delay) * direction_;
}

}  // namespace clothwind::sim
