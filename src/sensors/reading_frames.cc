#include "sensors/reading_frames.h"

namespace clothwind::sensors {

std::string ReadingFrames::FrameFor(const WindReading& r, const std::string& instrument_frame) {
  const bool earth_type = r.source == "nmea_mwd" || r.source == "fine_offset";
  const bool earth = r.reference == AngleReference::kEarth || r.reference == AngleReference::kMagnetic ||
                     (r.reference == AngleReference::kNone && earth_type);
  if (earth) saw_earth_ = true;
  if (r.reference == AngleReference::kInstrument) saw_instrument_ = true;
  if (r.reference == AngleReference::kMagnetic) saw_magnetic_ = true;
  const std::string frame = earth && !earth_frame_id_.empty() ? earth_frame_id_ : instrument_frame;
  if (earth) last_earth_frame_ = frame;
  return frame;
}

std::vector<std::string> ReadingFrames::Warnings(bool declination_known, const std::string& frame_id,
                                                 bool topic_input) const {
  std::vector<std::string> warnings;
  if (saw_magnetic_ && !declination_known)
    warnings.push_back("magnetic bearings (MWD) published without direction: set ~magnetic_declination");
  // Compass bearings in the instrument's default frame name, which config/anemometer.yaml defines
  // as x towards the instrument's north mark: a TF tree that mounts it so turns every bearing by
  // the mark's heading. In topic mode a record's own frame wins over ~frame_id (a replay keeps the
  // recorded one): the advice to set ~frame_id changed nothing there.
  if (saw_earth_ && !saw_instrument_ && last_earth_frame_ == default_frame_id_)
    warnings.push_back("compass bearings published in frame " + last_earth_frame_ +
                       " (the instrument's default name): set ~earth_frame_id" +
                       (topic_input ? std::string() : std::string(" or ~frame_id")) + " to the ENU frame they are in");
  if (saw_earth_ && saw_instrument_ && earth_frame_id_.empty())
    warnings.push_back("instrument-relative and earth-referenced directions share frame " + frame_id +
                       ": set ~earth_frame_id");
  return warnings;
}

}  // namespace clothwind::sensors
