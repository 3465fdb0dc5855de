// Which frame an anemometer reading's direction is published in, and what the frames seen so far
// say is wrong with the node's frame settings. ROS-free; nodes/anemometer_node.cc publishes and
// reports diagnostics from it (docs/anemometer.md, "Frames").
//
// Earth-referenced bearings (NMEA MWD, a north-aligned Fine Offset station) go in the earth frame
// when one is set, instrument-relative angles in the instrument's frame. A reading of an earth type
// without a direction (calm, or bearings left empty) goes with its type's others: in the
// instrument's frame, a station's calm first reading made wind_display adopt that frame and leave
// every later bearing out of its arrow for the whole session.
#ifndef CLOTHWIND_SENSORS_READING_FRAMES_H_
#define CLOTHWIND_SENSORS_READING_FRAMES_H_

#include <string>
#include <utility>
#include <vector>

#include "sensors/wind_reading.h"

namespace clothwind::sensors {

class ReadingFrames {
 public:
  // earth_frame_id: ~earth_frame_id ("" = none: bearings go in the instrument's frame).
  // default_frame_id: ~frame_id's default name (the instrument's own frame), which a TF tree
  // mounts with x towards the instrument's north mark.
  ReadingFrames(std::string earth_frame_id, std::string default_frame_id)
      : earth_frame_id_(std::move(earth_frame_id)), default_frame_id_(std::move(default_frame_id)) {}

  // The frame reading r's direction is in, given the frame of the instrument that read it
  // (~frame_id, or a replayed record's own); notes what it saw for Warnings.
  std::string FrameFor(const WindReading& r, const std::string& instrument_frame);

  // What is wrong with the frame settings, given the readings seen so far, as diagnostics WARN
  // texts (empty: nothing).
  // Inputs:
  //   declination_known  ~magnetic_declination is set (magnetic bearings need it)
  //   frame_id           ~frame_id (named when both kinds of direction share it)
  //   topic_input        a replay: a record's own frame wins over ~frame_id
  std::vector<std::string> Warnings(bool declination_known, const std::string& frame_id, bool topic_input) const;

  bool saw_earth() const { return saw_earth_; }
  bool saw_instrument() const { return saw_instrument_; }
  bool saw_magnetic() const { return saw_magnetic_; }

 private:
  std::string earth_frame_id_, default_frame_id_;
  bool saw_earth_ = false, saw_instrument_ = false, saw_magnetic_ = false;
  std::string last_earth_frame_;  // the frame the last compass bearing went in
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_READING_FRAMES_H_
