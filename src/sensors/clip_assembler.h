#ifndef CLOTHWIND_SENSORS_CLIP_ASSEMBLER_H_
#define CLOTHWIND_SENSORS_CLIP_ASSEMBLER_H_

#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace clothwind::sensors {

// One frame of a clip, after resampling and preprocessing.
struct ClipFrame {
  int64_t tick = 0;           // output tick number (consecutive within one unbroken stream)
  double stamp = 0.0;         // tick time [s] (exactly 1/rate apart within a clip)
  double source_stamp = 0.0;  // stamp of the camera frame shown [s]
  cv::Mat image;              // size x size CV_8UC1, or CV_8UC3 BGR for colour clips (shared, never modified)
};

// N_t consecutive frames.
struct AssembledClip {
  uint64_t sequence = 0;  // running number of clips from this assembler (0, 1, ...)
  std::vector<ClipFrame> frames;
};

// Cuts an unbroken stream of resampled frames into clips of num_frames consecutive frames, one
// every `stride` frames: after a (re)start, clips end at frames num_frames, num_frames + stride,
// num_frames + 2 * stride, ... (stride == num_frames: back to back, stride < num_frames: overlapping,
// stride > num_frames: frames between clips are skipped). A break (a gap in the camera stream, or a
// tick that does not follow the previous one) discards the partial clip and restarts the count.
class ClipAssembler {
 public:
  // num_frames >= 1 (30), stride >= 1 (30).
  ClipAssembler(int num_frames, int stride);

  // Adds the next frame; returns the clip it completes, if any. A frame whose tick is not the
  // previous tick + 1 breaks the clip first (then starts the new one).
  std::optional<AssembledClip> Add(ClipFrame frame);

  // Discards the partial clip (a gap); the next frame starts a new one.
  void Break();

  uint64_t clips_made() const { return next_sequence_; }
  uint64_t breaks() const { return breaks_; }
  // Frames that were in partial clips when they were broken (lost to gaps): frames the next clip
  // would have held, not those a stride wider than num_frames skips anyway.
  uint64_t frames_discarded() const { return frames_discarded_; }
  int num_frames() const { return num_frames_; }
  int stride() const { return stride_; }

 private:
  int num_frames_;
  int stride_;
  std::deque<ClipFrame> window_;  // the last num_frames frames
  int64_t since_restart_ = 0;     // frames added since the last (re)start
  int64_t since_emit_ = 0;        // frames in the partial clip not yet part of any emitted clip
  uint64_t next_sequence_ = 0;
  uint64_t breaks_ = 0;
  uint64_t frames_discarded_ = 0;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CLIP_ASSEMBLER_H_
