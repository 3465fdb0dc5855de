#ifndef CLOTHWIND_SENSORS_FRAME_RESAMPLER_H_
#define CLOTHWIND_SENSORS_FRAME_RESAMPLER_H_

#include <cstdint>
#include <vector>

namespace clothwind::sensors {

// Decides, from input frame stamps alone, which input frame becomes each output frame of a fixed
// rate (25 fps as the paper's clips). The output grid is anchored at the first frame after a
// (re)start: ticks t0 + k / rate. Each tick takes the NEAREST input frame by stamp (ties go to
// the earlier frame); frames are never blended, so every output frame is a real, sharp camera
// image (a blend of two 60 fps frames ghosts the moving cloth, which the simulator never shows).
//
// Streaming: a tick tau is decided once a frame stamped >= tau has arrived (the previous frame
// and the new one bracket it), so the resampler needs no look-ahead beyond one input frame.
//
// Gaps: when two consecutive input frames are further apart than gap_tolerance, the ticks between
// them would repeat a stale frame; instead the resampler reports a gap and restarts its grid at
// the new frame, so the clip assembler breaks the clip rather than stitching across the hole.
// A stamp that does not increase (duplicate or out of order) is dropped; a jump back by more
// than gap_tolerance (a bag restarted, a clock reset) restarts the grid as well.
class FrameResampler {
 public:
  // One output frame.
  struct Tick {
    int64_t index;         // tick number since the grid's anchor (0, 1, 2, ...)
    double stamp;          // tick time t0 + index / rate [s]
    double source_stamp;   // stamp of the input frame chosen for it [s]
    bool from_previous;    // true: the frame before the one just pushed; false: the one pushed
  };
  // What one pushed input frame produced.
  struct Result {
    std::vector<Tick> ticks;  // ticks decided by this frame, in time order
    bool gap = false;         // the grid restarted at this frame because of a hole in the stream
    bool restarted = false;   // the grid restarted at this frame (first frame, gap or time jump)
    bool dropped = false;     // the frame was ignored (stamp not after the previous one)
    bool jumped_back = false; // the grid restarted because time went back by > gap_tolerance
  };

  // Inputs:
  //   rate_hz         output rate [Hz] > 0 (25)
  //   gap_tolerance   largest interval between consecutive input frames still bridged [s] > 0
  FrameResampler(double rate_hz, double gap_tolerance);

  // Pushes the next input frame's stamp [s] and returns the output ticks it decides. A tick may
  // use the previously pushed frame (from_previous) — the caller keeps that one frame around.
  Result Push(double stamp);

  // Forgets the stream: the next frame restarts the grid.
  void Reset();

  double rate() const { return rate_; }
  double gap_tolerance() const { return gap_tolerance_; }

 private:
  double TickStamp(int64_t index) const { return anchor_ + static_cast<double>(index) / rate_; }

  double rate_;
  double gap_tolerance_;
  bool started_ = false;
  double anchor_ = 0.0;        // stamp of tick 0 [s]
  double previous_ = 0.0;      // stamp of the last accepted frame [s]
  int64_t next_tick_ = 0;      // first tick not decided yet
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_FRAME_RESAMPLER_H_
