#include "sensors/wind_direction_frame.h"

#include <cmath>
#include <utility>

namespace clothwind::sensors {

WindDirectionFrameGate::WindDirectionFrameGate(std::string frame_id)
    : frame_id_(std::move(frame_id)), adopt_(frame_id_.empty()) {}

bool WindDirectionFrameGate::Admit(const std::string& frame_id, double direction) {
  if (!Accepts(frame_id, direction)) {
    ++rejected_;
    last_rejected_frame_ = frame_id;
    return false;
  }
  // A direction that is not finite (NaN: none; inf: a broken instrument's) names no frame.
  if (adopt_ && std::isfinite(direction)) {
    frame_id_ = frame_id;
    adopt_ = false;
  }
  return true;
}

bool WindDirectionFrameGate::Accepts(const std::string& frame_id, double direction) const {
  return !std::isfinite(direction) || adopt_ || frame_id == frame_id_;
}

}  // namespace clothwind::sensors
