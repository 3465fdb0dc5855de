// How sdn_node is told the way a flag flies: its ~flag_flies, ~camera_heading,
// ~camera_heading_frame and ~end_on_angle, checked together once at start (ROS-free, so every
// combination is unit-tested; the node reads the parameters and reports the errors).
#ifndef CLOTHWIND_LEARN_FLAG_FLIES_SETTINGS_H_
#define CLOTHWIND_LEARN_FLAG_FLIES_SETTINGS_H_

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "learn/fly_direction.h"

namespace clothwind::learn {

struct FlagFliesSettings {
  std::optional<FlagFlies> told;  // right, left or auto as given; unset: the model's own default
  bool follow_wind = false;       // wind: each clip's way from the anemometer's direction
  bool pose_from_tf = false;      // follow_wind with no ~camera_heading: the camera's pose from tf
  double camera_heading = std::nan("");  // [rad] the level camera's heading, when follow_wind uses it
  double end_on = 20.0 * M_PI / 180.0;   // [rad] a wind this near the optical axis has no side
  // Parameters out of range or read but unused, each named: an ERROR, and its default used.
  std::vector<std::string> errors;
};

// Inputs:
//   flag_flies            ~flag_flies: "right", "left", "auto", "wind" or "" (unset)
//   camera_heading        ~camera_heading [rad], nothing when unset (NaN when set to .nan)
//   camera_heading_frame  ~camera_heading_frame ("" unset)
//   end_on_deg            ~end_on_angle [deg], 0..90
// Returns the settings; a bad value is named in `errors` and leaves its default: an end-on angle
// outside 0..90 is 20 deg, a heading not finite or beyond 2 pi (degrees given?) is not followed, a
// heading without wind or a heading frame without a heading is said to be unused, and an unknown
// ~flag_flies leaves the model's way.
FlagFliesSettings ReadFlagFliesSettings(const std::string& flag_flies, std::optional<double> camera_heading,
                                        const std::string& camera_heading_frame, double end_on_deg);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FLAG_FLIES_SETTINGS_H_
