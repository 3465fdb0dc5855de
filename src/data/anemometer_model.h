#ifndef CLOTHWIND_DATA_ANEMOMETER_MODEL_H_
#define CLOTHWIND_DATA_ANEMOMETER_MODEL_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "sensors/synthetic_session.h"
#include "sim/wind_field.h"

namespace clothwind::data {

// A cup anemometer with a wind vane, as a sensor model between a wind field and the NMEA MWV
// sentences a field station sends:
//  - sampled at one point of the field (the station's position), every sample_dt;
//  - cups: a first-order response with a distance constant, ds/dt = (|u_h| - s) / tau with
//    tau = distance_constant / max(|u_h|, 0.5 m/s) (cups follow fast wind faster), and a
//    starting threshold below which they stand still;
//  - vane: a first-order response of the horizontal direction with time constant vane_tau;
//  - each report averages the cup speed over the last 1/rate seconds, adds Gaussian noise
//    (noise_std + noise_relative × reading), and is rounded as the sentence writes it (0.01 m/s,
//    0.1 deg); the sentence arrives `latency` after the interval ends.
struct AnemometerModelParams {
  Eigen::Vector3d position = Eigen::Vector3d(0.0, -2.0, 1.0);  // [m], simulator frame
  double rate = 1.0;               // sentences per second [Hz]
  double sample_dt = 0.05;         // field sampling step [s]
  double distance_constant = 2.5;  // cups [m] (typical 2-3 m)
  double threshold = 0.3;          // starting speed [m/s]
  double vane_tau = 1.0;           // [s]
  double noise_std = 0.05;         // [m/s]
  double noise_relative = 0.01;    // [-]
  double latency = 0.05;           // [s]
  double direction_from = 270.0;   // MWV angle of a wind blowing along +x [deg]
  uint64_t seed = 1;
};

// Runs the model over [0, duration] of the field and returns the sentences with stamps
// start_time + k / rate + latency (k = 1, 2, ...; those arriving after start_time + duration
// are dropped, as a recording that stops then would). The MWV angle of a wind blowing along
// direction phi (counter-clockwise from +x) is direction_from - phi.
// Throws std::invalid_argument on non-positive rate, sample_dt, distance constant or duration.
std::vector<sensors::SyntheticReading> SimulateAnemometer(const sim::WindField& field,
                                                          const AnemometerModelParams& params,
                                                          double start_time, double duration);

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_ANEMOMETER_MODEL_H_
