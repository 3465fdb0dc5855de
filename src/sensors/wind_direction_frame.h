// Which frame a clip's mean wind direction is in.
//
// A clip's label averages the directions of the anemometer readings in its window
// (wind_label.h), and each reading's direction is an angle in its own header.frame_id. Readings in
// two frames (an instrument sending relative MWV in its own frame and true MWD in an ENU frame,
// two anemometers on one topic) averaged together give an angle in neither frame. The gate keeps
// one frame for the directions: a fixed one (~wind_frame_id), or the first frame that comes with a
// direction. Readings from any other frame keep their speed (a speed has no frame) and lose their
// direction, and are counted so the node can say so.
#ifndef CLOTHWIND_SENSORS_WIND_DIRECTION_FRAME_H_
#define CLOTHWIND_SENSORS_WIND_DIRECTION_FRAME_H_

#include <cstdint>
#include <string>

namespace clothwind::sensors {

class WindDirectionFrameGate {
 public:
  // Inputs:
  //   frame_id  the frame directions must be in; "" adopts the frame of the first reading that has
  //             a direction
  explicit WindDirectionFrameGate(std::string frame_id = "");

  // Whether a reading's direction may be averaged into labels.
  // Inputs:
  //   frame_id   the reading's header.frame_id
  //   direction  its direction [rad], NaN when it has none (always admitted: nothing to mix)
  // Returns true when the direction is NaN or in the gate's frame (adopting frame_id when none is
  // set yet); false otherwise, counting the reading in rejected().
  bool Admit(const std::string& frame_id, double direction);

  // Whether Admit would take the reading, without adopting a frame or counting: a caller that may
  // still refuse the reading (a stamp in the future) adopts the frame only with one it keeps.
  bool Accepts(const std::string& frame_id, double direction) const;

  // The frame of admitted directions; "" until one is known.
  const std::string& frame_id() const { return frame_id_; }
  // Readings whose direction was refused, and the frame of the latest one.
  uint64_t rejected() const { return rejected_; }
  const std::string& last_rejected_frame() const { return last_rejected_frame_; }

 private:
  std::string frame_id_;
  bool adopt_;
  uint64_t rejected_ = 0;
  std::string last_rejected_frame_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_WIND_DIRECTION_FRAME_H_
