#ifndef CLOTHWIND_SIM_WIND_SPEC_H_
#define CLOTHWIND_SIM_WIND_SPEC_H_

#include <memory>

#include <Eigen/Core>

#include "sim/gust_wind.h"
#include "sim/shear_wind.h"
#include "sim/turbulent_wind.h"
#include "sim/wind_field.h"

namespace clothwind::sim {

// A scene's `wind` block: ArcSim's keys (velocity, density, drag) plus our field extensions
// (shear, turbulence, gusts; docs/scenes.md). Plain data, so a caller can set it in code.
struct WindSpec {
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // mean wind at the reference height [m/s]
  double density = 1.0;  // ArcSim's normal-pressure coefficient (air density-like) [kg/m^3]
  double drag = 0.0;     // ArcSim's tangential drag coefficient [kg/(m^2 s)]
  ShearProfile shear;
  TurbulenceParams turbulence;  // intensity 0: none
  GustParams gusts;             // rate or amplitude 0: none

  // Sets one seed for every random part (each gets its own derived stream).
  void SetSeed(uint64_t seed);
};

// Builds the field shear × mean + turbulence + gusts that `spec` describes (a SteadyWind when
// it has neither shear, turbulence nor gusts; a calm wind, velocity 0, has neither turbulence
// nor gusts: both are relative to the wind's direction). The returned field is immutable and
// thread-safe. Throws std::invalid_argument for bad parameters (a non-finite velocity, a
// negative or non-finite turbulence intensity or gust rate, a non-finite gust amplitude, and
// what the parts' constructors refuse).
std::shared_ptr<const WindField> MakeWindField(const WindSpec& spec);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_WIND_SPEC_H_
