#ifndef CLOTHWIND_SIM_FLAG_METRICS_H_
#define CLOTHWIND_SIM_FLAG_METRICS_H_

#include <Eigen/Core>

#include "sim/trajectory_io.h"

namespace clothwind::sim {

// Landmarks of a rectangular flag, found in material (rest) space: the hoist is the edge of
// smallest u, the fly edge that of largest u; "upper" is largest v (the scene transform maps
// material v to height for the flag scenes).
struct FlagLandmarks {
  int hoist_mid = -1;   // vertex nearest material (u_min, v_mid)
  int fly_mid = -1;     // vertex nearest material (u_max, v_mid)
  int fly_upper = -1;   // vertex nearest material (u_max, v_max): the free upper corner
};

// Inputs:
//   uv  #V by 2 material coordinates [m]
FlagLandmarks FindFlagLandmarks(const Eigen::MatrixX2f& uv);

// How a flag behaved over a window of a trajectory (the quantities of
// /work/shared/reference/arcsim.md's table).
struct FlagMotion {
  double droop_deg = 0;          // mean angle below horizontal of the chord hoist mid -> fly mid [deg]
  double lateral_rms = 0;        // fly corner's horizontal motion across the wind, RMS about its mean [m]
  double vertical_rms = 0;       // fly corner's vertical motion, RMS about its mean [m]
  // Frequency of the fly corner's motion (lateral + vertical): the power-weighted mean frequency
  // (spectral centroid) over 0.2-5 Hz [Hz]. A centroid rather than the single highest bin: a
  // flapping flag's spectrum is broad and its highest bin jumps between neighbours of a short
  // clip, while the centroid moves smoothly with the wind.
  double dominant_hz = 0;
  double peak_hz = 0;            // the single strongest bin in 0.2-5 Hz [Hz]
  double peak_fraction = 0;      // that bin's share of the 0.2-5 Hz power (1: a pure tone) [-]
  int frames = 0;
};

// Measures a flag's motion over frames [first, end) of a trajectory.
// Inputs:
//   t          trajectory (z up)
//   wind_dir   3-vector, mean wind direction (horizontal; "lateral" is horizontal and across it)
//   first      first frame of the window (e.g. skip the start-up transient)
// Spectra are periodograms (mean removed, Hann window) of frames [first, end).
FlagMotion MeasureFlagMotion(const Trajectory& t, const Eigen::Vector3d& wind_dir, int first);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_FLAG_METRICS_H_
