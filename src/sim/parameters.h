#ifndef CLOTHWIND_SIM_PARAMETERS_H_
#define CLOTHWIND_SIM_PARAMETERS_H_

#include <array>
#include <string>

#include <Eigen/Core>

#include "sim/material.h"
#include "sim/wind_spec.h"

namespace clothwind::sim {

// The paper's parameter vector theta = (theta_i, theta_e): 16 intrinsic parameters (area weight
// and the 3 x 5 bending table) and the wind speed, as plain numbers a caller can set without
// editing files. Values are the ones the simulator uses, i.e. AFTER the scene's material
// multipliers (thicken, density_mult, bending_mult): theta[0] of ArcSim's flag scene is
// 2 x 0.284 = 0.568 kg/m^2.
//
//   index  name            unit     meaning
//   0      area_weight     kg/m^2   Material::density
//   1+5d+c bending_d<d>_c<c> N m    Material::bending[d][c]; d: hinge direction 0, 45, 90 deg;
//                                   c: curvature 0, 10, 20, 30, 40 1/m
//   16     wind_speed      m/s      |mean wind| along the scene's wind direction
constexpr int kNumParameters = 17;
constexpr int kAreaWeightIndex = 0;
constexpr int kBendingIndex = 1;
constexpr int kWindSpeedIndex = 16;
using Theta = Eigen::Matrix<double, kNumParameters, 1>;

// Names (as in the table above) and units of the entries.
const std::array<std::string, kNumParameters>& ParameterNames();
const std::array<std::string, kNumParameters>& ParameterUnits();

// Index of the entry called `name`; throws std::invalid_argument listing the names if unknown.
int ParameterIndex(const std::string& name);

// Reads theta from a material and a wind.
// Inputs:
//   material  material with multipliers applied
//   wind      the scene's wind (its mean velocity's norm is the wind speed)
Theta ThetaFrom(const Material& material, const WindSpec& wind);

// Writes theta into a material and a wind. The wind keeps its direction (+x if it was zero) and
// gets speed theta[16]; turbulence and gusts keep their parameters: turbulence scales with the
// speed (its intensity is relative), gusts do not (their amplitude is in m/s), and a calm wind
// (speed 0) has neither (MakeWindField).
// Inputs:
//   theta  17 values (area weight > 0, bending > 0, wind speed >= 0, all finite)
// Outputs:
//   material  density and bending replaced (stretching untouched)
//   wind      velocity replaced
// Throws std::invalid_argument naming the entry when a value is out of range.
void ApplyTheta(const Theta& theta, Material* material, WindSpec* wind);

// Throws std::invalid_argument naming the first entry that is non-finite or out of range.
void ValidateTheta(const Theta& theta);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_PARAMETERS_H_
