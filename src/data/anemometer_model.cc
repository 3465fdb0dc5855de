#include "data/anemometer_model.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/random.h"

namespace clothwind::data {

std::vector<sensors::SyntheticReading> SimulateAnemometer(const sim::WindField& field,
                                                          const AnemometerModelParams& p,
                                                          double start_time, double duration) {
  if (!(p.rate > 0 && p.sample_dt > 0 && p.distance_constant > 0 && p.vane_tau > 0 && duration > 0))
    throw std::invalid_argument("anemometer model: rate, sample_dt, distance_constant, vane_tau and duration must be > 0");
  Rng rng(HashSeed(p.seed, 0xa4e3));
  const double interval = 1.0 / p.rate;
  const int per_interval = std::max(1, static_cast<int>(std::lround(interval / p.sample_dt)));
  const double dt = interval / per_interval;
  auto horizontal = [&](double t) {
    const Eigen::Vector3d v = field.Velocity(p.position, t);
    return Eigen::Vector2d(v.x(), v.y());
  };
  Eigen::Vector2d h = horizontal(0.0);
  double cups = h.norm() < p.threshold ? 0.0 : h.norm();  // started in equilibrium
  Eigen::Vector2d vane = h.norm() > 0 ? Eigen::Vector2d(h / h.norm()) : Eigen::Vector2d(1, 0);
  std::vector<sensors::SyntheticReading> out;
  const int intervals = static_cast<int>(std::floor(duration * p.rate + 1e-9));
  for (int k = 1; k <= intervals; ++k) {
    double sum = 0;
    for (int i = 1; i <= per_interval; ++i) {
      const double t = (k - 1) * interval + i * dt;
      h = horizontal(t);
      const double speed = h.norm();
      // Exact step of the linear response over dt with the current time constant.
      const double tau = p.distance_constant / std::max(speed, 0.5);
      const double target = speed < p.threshold && cups < p.threshold ? 0.0 : speed;
      cups = target + (cups - target) * std::exp(-dt / tau);
      // Below the starting speed, with the wind below it too, friction stops the cups (the decay
      // alone would only approach 0, and a calm after a gust kept reading noise).
      if (target == 0.0 && cups < p.threshold) cups = 0.0;
      if (speed > 1e-9) {
        const double a = std::exp(-dt / p.vane_tau);
        vane = a * vane + (1 - a) * (h / speed);
        if (vane.norm() > 1e-12) vane.normalize();
      }
      sum += cups;
    }
    sensors::SyntheticReading r;
    double reading = sum / per_interval;
    // Noise only while the cups turn: stopped cups read 0 (noise clamped at 0 gave calm air a
    // +0.02 m/s bias). Drawn either way, so the stream, and every later reading, stays the same.
    const double noise = (p.noise_std + p.noise_relative * reading) * rng.Normal();
    if (reading > 0) reading += noise;
    r.speed = std::round(std::max(0.0, reading) * 100.0) / 100.0;
    const double phi = std::atan2(vane.y(), vane.x()) * 180.0 / M_PI;
    double angle = std::fmod(p.direction_from - phi, 360.0);
    if (angle < 0) angle += 360.0;
    r.angle = std::fmod(std::round(angle * 10.0) / 10.0, 360.0);
    r.measured_at = start_time + k * interval;
    r.stamp = r.measured_at + p.latency;
    r.sentence = sensors::FormatMwvSentence(r.angle, r.speed);
    if (r.stamp <= start_time + duration) out.push_back(r);
  }
  return out;
}

}  // namespace clothwind::data
