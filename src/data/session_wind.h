#ifndef CLOTHWIND_DATA_SESSION_WIND_H_
#define CLOTHWIND_DATA_SESSION_WIND_H_

#include <memory>

#include <Eigen/Core>

#include "sensors/synthetic_session.h"
#include "sim/turbulent_wind.h"
#include "sim/wind_field.h"

namespace clothwind::data {

// The wind of a rendered field session as a field the cloth simulator and the anemometer both
// sample: the session's wind speed history (sensors::SyntheticWind: a mean drifting over minutes
// plus a gusty fluctuation) blowing along the session's current direction, plus frozen von
// Kármán turbulence (sim::TurbulentWind) for the differences between points in space, so an
// anemometer a few metres from the flag sees its own gusts.
//
// Frame: the simulator's (z up; the flag's hoist on the z axis); the mean wind blows along +x
// rotated about z by the direction's deviation from its session mean (MWV angle
// direction_from): deviation = direction_from - FromAngle(t), so a larger MWV angle turns the
// wind clockwise seen from above. t is seconds since the session start.
class SessionWindField final : public sim::WindField {
 public:
  // Inputs:
  //   wind            the session's wind (kept by reference-counted copy)
  //   direction_from  the session's mean MWV angle [deg]
  //   turbulence      spatial turbulence (intensity relative to mean_speed, length scale, seed)
  //   mean_speed      the session's long-term mean [m/s] (sets the turbulence's sigma and advection)
  SessionWindField(std::shared_ptr<const sensors::SyntheticWind> wind, double direction_from,
                   const sim::TurbulenceParams& turbulence, double mean_speed);

  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const override;

  // Horizontal direction of the mean wind at t (unit 3-vector, z = 0).
  Eigen::Vector3d Direction(double t) const;

 private:
  std::shared_ptr<const sensors::SyntheticWind> wind_;
  double direction_from_;
  std::unique_ptr<sim::TurbulentWind> turbulence_;  // null: none
};

// A field shifted in time: Velocity(x, t) = base(x, t + offset). The simulator counts time from
// 0 at its start, which for a session lies `warmup` seconds before the session's start.
class TimeShiftedWind final : public sim::WindField {
 public:
  TimeShiftedWind(std::shared_ptr<const sim::WindField> base, double offset)
      : base_(std::move(base)), offset_(offset) {}
  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const override {
    return base_->Velocity(x, t + offset_);
  }

 private:
  std::shared_ptr<const sim::WindField> base_;
  double offset_;
};

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_SESSION_WIND_H_
