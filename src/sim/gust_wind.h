#ifndef CLOTHWIND_SIM_GUST_WIND_H_
#define CLOTHWIND_SIM_GUST_WIND_H_

#include <cstdint>
#include <vector>

#include "sim/wind_field.h"

namespace clothwind::sim {

struct GustParams {
  double rate = 0.0;              // mean gusts per second (Poisson arrivals) [1/s]
  double amplitude = 0.0;         // mean peak speed added along the wind [m/s]
  double amplitude_spread = 0.5;  // peak ~ Uniform(amplitude (1 - s), amplitude (1 + s))
  double duration = 2.0;          // rise and fall time of one gust [s]
  double horizon = 3600.0;        // gusts are drawn for t in [0, horizon) [s]
  // Whether the scene set the horizon. When it did not, Simulate draws gusts over the whole run
  // (warm-up and --duration included): an hour's default once ended the gusts of longer runs.
  bool horizon_given = false;
  uint64_t seed = 0;
};

struct Gust {
  double start;      // [s], at the advection origin x . e = 0
  double amplitude;  // peak speed [m/s]
};

// Discrete gusts of the "1 − cos" shape, u(t) = A/2 (1 − cos(2 pi (t − t0)/T)) for
// t0 <= t <= t0 + T, added along `direction` and arriving later downstream (a gust front that
// travels with the mean wind: t is replaced by t − x.e/|U|). Start times are a Poisson process
// drawn from the seed; overlapping gusts add.
class GustWind final : public WindField {
 public:
  // Inputs:
  //   params         rate, amplitude, duration, seed
  //   mean_velocity  U [m/s]: gust direction e = U/|U| (x if U = 0; MakeWindField makes no gusts
  //                  for a calm wind) and front speed |U|
  GustWind(const GustParams& params, const Eigen::Vector3d& mean_velocity);

  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const override;

  // The gust speed (along e) at the advection origin at time t [m/s].
  double Speed(double t) const;

  const std::vector<Gust>& gusts() const { return gusts_; }  // sorted by start

 private:
  GustParams params_;
  Eigen::Vector3d direction_;
  double front_speed_;
  std::vector<Gust> gusts_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_GUST_WIND_H_
