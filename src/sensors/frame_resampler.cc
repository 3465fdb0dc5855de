#include "sensors/frame_resampler.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace clothwind::sensors {

FrameResampler::FrameResampler(double rate_hz, double gap_tolerance)
    : rate_(rate_hz), gap_tolerance_(gap_tolerance) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
    throw std::invalid_argument("FrameResampler: rate must be > 0 Hz, got " + std::to_string(rate_hz));
  if (!(gap_tolerance > 0.0))
    throw std::invalid_argument("FrameResampler: gap_tolerance must be > 0 s, got " +
                                std::to_string(gap_tolerance));
}

void FrameResampler::Reset() {
  started_ = false;
  next_tick_ = 0;
}

FrameResampler::Result FrameResampler::Push(double stamp) {
  Result result;
  if (!std::isfinite(stamp)) {
    result.dropped = true;
    return result;
  }
  if (started_) {
    const double dt = stamp - previous_;
    if (dt <= 0.0 && -dt <= gap_tolerance_) {  // duplicate or slightly out of order: ignore it
      result.dropped = true;
      return result;
    }
    if (dt > gap_tolerance_) result.gap = true;
    if (dt < 0.0) result.jumped_back = true;
    if (dt > gap_tolerance_ || dt < 0.0) started_ = false;  // hole or jump back: restart
  }
  if (!started_) {
    started_ = true;
    result.restarted = true;
    anchor_ = stamp;
    previous_ = stamp;
    next_tick_ = 1;
    result.ticks.push_back({0, stamp, stamp, false});
    return result;
  }
  // Every undecided tick up to this frame's stamp lies between the previous frame and this one:
  // take whichever is nearer (ties: the earlier frame, so the choice never depends on jitter
  // beyond the midpoint).
  // A 1 us epsilon keeps a tick that coincides with a frame (every 5th frame of 30 fps at 25 fps)
  // from slipping to the next frame through rounding of t0 + k / rate (doubles near 1.7e9 s, an
  // epoch stamp, resolve ~0.2 us).
  constexpr double eps = 1e-6;
  while (TickStamp(next_tick_) <= stamp + eps) {
    const double tau = TickStamp(next_tick_);
    const bool previous_nearer = (tau - previous_) <= (stamp - tau) + eps;
    result.ticks.push_back({next_tick_, tau, previous_nearer ? previous_ : stamp, previous_nearer});
    ++next_tick_;
  }
  previous_ = stamp;
  return result;
}

}  // namespace clothwind::sensors
