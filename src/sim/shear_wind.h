#ifndef CLOTHWIND_SIM_SHEAR_WIND_H_
#define CLOTHWIND_SIM_SHEAR_WIND_H_

#include "sim/wind_field.h"

namespace clothwind::sim {

// Vertical profile of the mean wind near the ground.
struct ShearProfile {
  enum class Kind { kNone, kPower, kLog };
  Kind kind = Kind::kNone;
  double exponent = 1.0 / 7.0;     // power law alpha [-] (1/7: open terrain)
  double roughness = 0.03;         // log law roughness length z0 [m] (0.03: open grass)
  double reference_height = 4.6;   // height above ground where the mean wind is given [m]
  double ground_z = 0.0;           // world z of the ground [m] (a scene must give it with a profile)

  // Returns U(h)/U(reference_height) at world height z: (h/h_ref)^alpha or
  // ln(h/z0)/ln(h_ref/z0), with h = z - ground_z; 0 at or below the ground (or below z0 for
  // the log law); 1 for kNone.
  double Factor(double z) const;
};

// Mean wind `reference_velocity` [m/s] at the reference height, scaled with height by `profile`.
class ShearWind final : public WindField {
 public:
  ShearWind(const Eigen::Vector3d& reference_velocity, const ShearProfile& profile)
      : velocity_(reference_velocity), profile_(profile) {}
  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double) const override {
    return profile_.Factor(x.z()) * velocity_;
  }

 private:
  Eigen::Vector3d velocity_;
  ShearProfile profile_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_SHEAR_WIND_H_
