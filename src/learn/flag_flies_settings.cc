#include "learn/flag_flies_settings.h"

#include <stdexcept>

namespace clothwind::learn {

FlagFliesSettings ReadFlagFliesSettings(const std::string& flag_flies, std::optional<double> camera_heading,
                                        const std::string& camera_heading_frame, double end_on_deg) {
  FlagFliesSettings s;
  if (!(end_on_deg >= 0 && end_on_deg <= 90)) {
    s.errors.push_back("~end_on_angle must be 0 to 90 degrees, got " + std::to_string(end_on_deg));
    end_on_deg = 20;
  }
  s.end_on = end_on_deg * M_PI / 180.0;
  const bool wind = flag_flies == "wind";
  double heading = camera_heading.value_or(std::nan(""));
  if (camera_heading && !std::isfinite(heading)) {
    s.errors.push_back(std::string("~camera_heading is not a finite angle [rad]; ") +
                       (wind ? "~flag_flies wind is not followed" : "it is ignored"));
  } else if (std::isfinite(heading) && std::abs(heading) > 2 * M_PI) {
    s.errors.push_back("~camera_heading is " + std::to_string(heading) +
                       ", beyond 2 pi: it is in radians (degrees given?); ~flag_flies wind is not followed");
    heading = std::nan("");
  }
  if (wind) {
    // Unset: the pose in tf. Out of range: not followed (a heading in degrees is no pose to
    // replace silently).
    s.follow_wind = std::isfinite(heading) || !camera_heading;
    s.pose_from_tf = s.follow_wind && !std::isfinite(heading);
    s.camera_heading = heading;
    if (s.pose_from_tf && !camera_heading_frame.empty())
      s.errors.push_back("~camera_heading_frame is set without ~camera_heading: the camera's pose comes from tf, "
                         "in each clip's wind direction frame");
  } else if (std::isfinite(heading)) {
    // Read but unused: a ~camera_heading given without ~flag_flies wind read every clip as
    // filmed without a word (a flag flying left then reads ~2.5 m/s off).
    s.errors.push_back("~camera_heading is set but ~flag_flies is '" + flag_flies +
                       "', not wind: the anemometer's direction is not used to tell the way the flag flies");
  }
  if (!wind && !flag_flies.empty()) {
    try {
      s.told = FlagFliesFromName(flag_flies, "~flag_flies");
    } catch (const std::invalid_argument& e) {
      s.errors.push_back(std::string(e.what()) + " (or wind); the model's way is used");
    }
  }
  return s;
}

}  // namespace clothwind::learn
