#ifndef CLOTHWIND_SIM_TURBULENT_WIND_H_
#define CLOTHWIND_SIM_TURBULENT_WIND_H_

#include <array>
#include <cstdint>

#include "sim/wind_field.h"

namespace clothwind::sim {

// The turbulence a scene or `simulate --turbulence` may ask for: an intensity up to 10 (outdoors
// ~0.1-0.3) and an integral length scale from 1 cm to 10 km (outdoors ~10-300 m). Below a
// centimetre the field's wavenumbers outrun any time step, and near 1e-300 m they overflow: such
// a run failed steps later with "non-finite force", naming neither.
inline constexpr double kMaxTurbulenceIntensity = 10;
inline constexpr double kMinTurbulenceLengthScale = 0.01;  // [m]
inline constexpr double kMaxTurbulenceLengthScale = 1e4;   // [m]

struct TurbulenceParams {
  double intensity = 0.0;     // I = sigma_u / |U| [-] (longitudinal)
  double length_scale = 10.0; // longitudinal integral length scale L_u [m]
  // sigma of the (along-wind, cross-wind, vertical) components relative to sigma_u;
  // IEC 61400-1's ratios by default.
  std::array<double, 3> component_ratios{1.0, 0.8, 0.5};
  int modes = 128;             // number of random Fourier modes
  uint64_t seed = 0;
};

// Frozen (Taylor) turbulence advected with the mean wind: the zero-mean fluctuation
//   u'(x, t) = sum_n A_n cos(K_n . (x - U t) + phi_n)
// of `modes` random Fourier modes whose wavenumbers are log-spaced shells, each with a random
// direction, a random polarisation perpendicular to it and a random phase, weighted by the
// isotropic von Kármán energy spectrum E(k) ∝ (k/k_e)^4 / (1 + (k/k_e)^2)^(17/6) with
// k_e = 0.7468 / L_u (so the longitudinal integral scale is L_u). The realised per-component
// variances are rescaled to exactly (I |U| ratio_i)^2, so a short clip sees the intended
// intensity. Same params and mean wind → the same field, bit for bit.
//
// Cost: one cos per mode per call, vectorised (Eigen arrays, float cosine after an exact
// reduction of the phase to [-pi, pi] in double): ~1 µs for 128 modes, ~3x the scalar loop.
// Values are reproducible bit for bit within a build; the float cosine limits their relative
// accuracy to ~1e-6.
class TurbulentWind final : public WindField {
 public:
  // Inputs:
  //   params         intensity, length scale, seed, ...
  //   mean_velocity  U [m/s], the advection velocity and the frame of the components
  //                  (along U, horizontal across U, up); sigma_u = I |U|.
  TurbulentWind(const TurbulenceParams& params, const Eigen::Vector3d& mean_velocity);

  // Returns the fluctuation u'(x, t) [m/s] (zero mean; add the mean wind separately).
  Eigen::Vector3d Velocity(const Eigen::Vector3d& x, double t) const override;

  // The model's longitudinal correlation f(r) = 2^(2/3)/Gamma(1/3) (k_e r)^(1/3) K_1/3(k_e r)
  // for separation r [m] along the wind (what the field's along-wind autocorrelation at lag
  // tau should follow with r = |U| tau).
  static double LongitudinalCorrelation(double r, double length_scale);

  const Eigen::Matrix3d& frame() const { return frame_; }  // columns: along, across, up

 private:
  Eigen::Vector3d mean_;
  Eigen::Matrix3d frame_;
  // Mode n: wavevector K_n [rad/m] (kx_, ky_, kz_), phase phi_n [rad], amplitude A_n [m/s]
  // (ax_, ay_, az_), stored as arrays so that Velocity() vectorises over modes.
  Eigen::ArrayXd kx_, ky_, kz_, phase_;
  Eigen::ArrayXf ax_, ay_, az_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_TURBULENT_WIND_H_
