#ifndef CLOTHWIND_SIM_WIND_FIELD_H_
#define CLOTHWIND_SIM_WIND_FIELD_H_

#include <memory>
#include <vector>

#include <Eigen/Core>

namespace clothwind::sim {

// Air velocity as a field over space and time. The simulator asks for it at face centroids every
// step, so the sim-to-real work can plug in effects (turbulence, gusts, shear, wakes) here without
// touching the cloth model. Implementations must be thread-safe for concurrent const calls.
//
// Implementations in this folder: SteadyWind (below), ShearWind (shear_wind.h), TurbulentWind
// (turbulent_wind.h), GustWind (gust_wind.h), and SumWind (below) to compose them; WindSpec +
// MakeWindField (wind_spec.h) builds the usual composition shear × mean + turbulence + gusts.
class WindField {
 public:
  virtual ~WindField() = default;

  // Inputs:
  //   x  3-vector, world position [m] (scene frame, z up)
  //   t  simulated time [s]
  // Returns the air velocity at (x, t) [m/s], 3-vector in the scene frame.
  virtual Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const = 0;
};

// The same velocity everywhere and always: ArcSim's wind.
class SteadyWind final : public WindField {
 public:
  explicit SteadyWind(const Eigen::Vector3d& velocity) : velocity_(velocity) {}
  Eigen::Vector3d Velocity(const Eigen::Vector3d&, double) const override { return velocity_; }

 private:
  Eigen::Vector3d velocity_;
};

// The sum of several fields (e.g. a sheared mean + turbulent fluctuation + gusts). Each part
// returns its own contribution; fluctuation fields return zero-mean velocities.
class SumWind final : public WindField {
 public:
  explicit SumWind(std::vector<std::shared_ptr<const WindField>> parts) : parts_(std::move(parts)) {}
  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const override {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (const auto& part : parts_) v += part->Velocity(x, t);
    return v;
  }
  const std::vector<std::shared_ptr<const WindField>>& parts() const { return parts_; }

 private:
  std::vector<std::shared_ptr<const WindField>> parts_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_WIND_FIELD_H_
