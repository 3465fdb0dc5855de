// Which way a flag flies across a clip, from the clip alone: a model trained without horizontal
// flips (train --no-flip) has only seen FlagSim's flags, which all fly toward the image's right,
// so a real flag flying left must be mirrored before it reads it.
#ifndef CLOTHWIND_LEARN_FLY_DIRECTION_H_
#define CLOTHWIND_LEARN_FLY_DIRECTION_H_

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace clothwind::learn {

enum class FlyDirection { kRight, kLeft };

// "right" / "left".
std::string FlyDirectionName(FlyDirection direction);

// How a clip is turned before a model reads it (SampleOptions::flag_flies, the node's
// ~flag_flies, eval's --flag-flies):
//   kRight  as filmed: the flag is taken to fly right, as FlagSim's do
//   kLeft   the flag flies left: every clip is mirrored
//   kAuto   each clip is mirrored when EstimateFlyDirection says its flag flies left
enum class FlagFlies { kRight, kLeft, kAuto };

// "right" / "left" / "auto".
std::string FlagFliesName(FlagFlies flag_flies);
// The inverse; throws std::invalid_argument naming `where` (an option or parameter) and the
// three accepted values.
FlagFlies FlagFliesFromName(const std::string& name, const std::string& where);

// The two cues and the decision they make. Both change sign exactly when the clip is mirrored.
struct FlyDirectionCues {
  // Skewness of the clip's motion across the image: the column sums of each pixel's temporal
  // standard deviation (less their 10th percentile, a still background's noise floor) taken as a
  // distribution over columns. The hoist is held by the pole and the fly end sweeps, so motion
  // grows toward the fly end and the distribution's long tail points at the pole: < 0 flies
  // right. Weak at the highest speeds, where a taut flag ripples evenly along its length.
  double motion_skewness = 0;
  // [rad/px] The angle of sum over pixels and temporal frequencies (bins 1 .. T/2 - 1) of
  // z(x + 1, y) conj(z(x, y)), z a pixel's temporal DFT: the phase step to the right neighbour.
  // Waves travel from the hoist to the fly end, and a wave travelling right has e^{-ikx} at
  // positive frequency: < 0 flies right. Weak at low speeds, where the flag hangs and sways.
  double phase_step = 0;
  // kSkewnessWeight * -motion_skewness + kPhaseWeight * -phase_step: > 0 (or 0) flies right.
  double score = 0;
  FlyDirection direction = FlyDirection::kRight;
};

// Weights of the cues in the score: a logistic regression without intercept (so a mirrored clip
// gets exactly the opposite score) of the first 30 frames of 625 flagsim-e5 training clips and
// their mirror images, at 64 px. The score is right for 91.3 % of 1344 test clips' centred
// windows (0-2 m/s: 73 %, 8-10 m/s: 99 %), where the skewness alone or the phase alone are right
// for ~91 % and ~86 % of first windows: too few for a model that misreads a flag flying left by
// 2.5 m/s (docs/sdn.md, "Flags that fly left").
constexpr double kSkewnessWeight = 7.417;
constexpr double kPhaseWeight = 3.335;

// Inputs:
//   frames  T >= 4 single-channel images (CV_8UC1 or CV_32FC1) of one size, rows x cols with
//           cols >= 3, in time order; the centred square a model reads, at its input size, is
//           what the weights were fitted on.
// Returns the cues and the direction. A still clip scores 0 and flies right (as filmed).
// Throws std::invalid_argument naming the frame and what was expected.
FlyDirectionCues EstimateFlyDirection(const std::vector<cv::Mat>& frames);

// Each pixel's standard deviation over time (population: divided by T), where a clip moves; the
// motion cues' skewness and the fly judge's map (fly_judge.h) both read it.
// Inputs: frames  T >= 1 CV_64FC1 images of one size, in any order.
// Returns a CV_64FC1 image of that size.
cv::Mat TemporalStd(const std::vector<cv::Mat>& frames);

// The way a flag flies in a camera's picture from the anemometer's wind direction, for a model that
// must be told (the clip's own motion is too often wrong). A flag flies downwind, so it flies to
// the picture's right when the air moves toward the camera's right.
// Inputs:
//   wind_direction  [rad] where the air blows TO, counter-clockwise about +z from +x of the
//                   anemometer's frame (WindMeasurement's convention; a clip's wind_direction_mean)
//   camera_heading  [rad] the camera's optical axis in the same frame and convention, the camera
//                   taken as level (its picture's right is the heading turned 90 deg clockwise)
//   end_on          [rad] >= 0: a wind within this angle of the optical axis, toward or away from
//                   the camera, shows the flag end-on, with no side to fly to
// Returns the way, or nothing when the wind is end-on or either angle is not finite.
std::optional<FlyDirection> FlyDirectionFromWind(double wind_direction, double camera_heading, double end_on);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FLY_DIRECTION_H_
