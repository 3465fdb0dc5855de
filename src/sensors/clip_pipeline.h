#ifndef CLOTHWIND_SENSORS_CLIP_PIPELINE_H_
#define CLOTHWIND_SENSORS_CLIP_PIPELINE_H_

#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "sensors/clip_assembler.h"
#include "sensors/clip_preprocess.h"
#include "sensors/clock_course.h"
#include "sensors/frame_resampler.h"
#include "sensors/wind_label.h"

namespace clothwind::sensors {

// Bounds of a clip's sizes (a 16K camera; the datasets' bound on frames per clip): sdn_node,
// train and eval refuse clips beyond them, so the clip buffer refuses to make them.
constexpr int kMaxClipSide = 16384;     // [px]
// The smallest clip: the network reads 64-96 px, and a clip of a few pixels holds no flag
// (sdn_node estimated a 1 x 1 clip at 6.4 m/s); sdn_node refuses smaller ones as malformed.
constexpr int kMinClipSide = 8;  // [px]
constexpr int kMaxClipFrames = 100000;

// Settings of the clip buffer (ROS parameters of clip_buffer_node of the same names).
struct ClipPipelineOptions {
  double frame_rate = 25.0;    // output rate [Hz]
  double gap_tolerance = 0.1;  // largest camera frame interval bridged [s]; beyond it the clip breaks
  int num_frames = 30;         // N_t
  int stride = 30;             // a clip every `stride` output frames
  int size = 300;              // output frame side [px]
  SquareRoi roi;               // crop in source pixels; size 0: centred square
  bool colour = false;         // frames bgr8 (for a model that reads colour) instead of mono8
  double label_window = 60.0;  // anemometer window before each clip's last frame [s]
  // A finished clip waits until the data (frame or reading stamps) has reached its end plus this
  // long [s] before it is labelled, so readings stamped inside its window that arrive a little late
  // still count. 1.5 s covers a 1 Hz anemometer's next reading plus transport.
  double label_delay = 1.5;
  // A frame or reading stamped more than this after the clock passed with it [s] is refused: one
  // stamp from a wrong clock would otherwise move the pipeline's time forward for good (every
  // later clip released at once and the readings it needs pruned as old).
  double max_future = 5.0;
};

// `now` of AddFrame/AddReading when there is no clock to compare with (stamps not checked).
inline constexpr double kNoClock = std::numeric_limits<double>::infinity();

// Throws std::invalid_argument naming the first option out of range (by its ROS parameter name)
// and what was expected.
void ValidateClipPipelineOptions(const ClipPipelineOptions& options);

// A clip with its label, ready to publish or record.
struct LabelledClip {
  AssembledClip clip;
  SquareRoi roi;             // resolved crop in source pixels
  int source_width = 0;      // source image size [px]
  int source_height = 0;
  double frame_rate = 25.0;  // [Hz]
  WindLabel label;
};

// Counters for diagnostics.
struct ClipPipelineStats {
  uint64_t frames_in = 0;         // camera frames pushed
  uint64_t frames_dropped = 0;    // ignored: stamp not after the previous one or in the future, or bad image
  uint64_t frames_out = 0;        // resampled frames produced
  uint64_t gaps = 0;              // holes in the camera stream longer than gap_tolerance
  uint64_t clips_made = 0;        // clips assembled
  uint64_t frames_discarded = 0;  // frames out thrown away with a clip a gap broke before it was whole
  uint64_t clips_released = 0;    // clips labelled and handed out
  uint64_t clips_unlabelled = 0;  // released with no reading in their window
  uint64_t readings_in = 0;       // usable anemometer readings
  uint64_t readings_late = 0;     // readings stamped inside an already released clip's window
  uint64_t frames_future = 0;     // frames refused: stamped more than max_future after the clock
  uint64_t readings_future = 0;   // readings refused for the same reason
  double last_future_lead = 0.0;  // how far after the clock the last refused stamp was [s]
  // Frames and readings of the previous pass still arriving after the clock went back (a looped
  // bag's /clock): stamped ahead of the clock but not past where it was before; dropped, not
  // counted as stamped in the future (they raised "a clock set wrong?" for 10 s after every loop).
  uint64_t frames_previous_pass = 0, readings_previous_pass = 0;
  uint64_t time_jumps = 0;        // camera time went back (a bag restarted or looped)
  // Frames stamped more than gap_tolerance before the frame before them that the next frame did
  // not follow (a lone stale stamp, not a new timeline): dropped, also counted in frames_dropped.
  uint64_t frames_stale = 0;
  uint64_t clips_at_jumps = 0;    // clips waiting at a jump, labelled with the readings held then
  uint64_t unlabelled_run = 0;    // clips released since the last one with a reading (0: it had one)
  double last_gap = 0.0;          // length of the last gap [s]
};

// Why camera frames keep arriving but make no clip, for diagnostics: most of them dropped as not
// after the previous frame (stamped 0, or a clock standing still), or most intervals longer than
// gap_tolerance (a camera slower than 1 / gap_tolerance fps). Both kept the node at OK, making
// nothing.
// Inputs:
//   since    the counters when the last clip was made (or at start)
//   now      the counters now
//   options  the pipeline's options (gap_tolerance, num_frames)
// Returns the reason, or "" while clips are made or too few frames (2 x num_frames) came to tell.
std::string ClipStallReason(const ClipPipelineStats& since, const ClipPipelineStats& now,
                            const ClipPipelineOptions& options);

// Why clips repeat camera frames, for diagnostics: more resampled frames out than camera frames
// in (by over 10 %), a camera slower than the clips' rate (a UVC camera that drops to 15 fps under
// auto-exposure) but within gap_tolerance. Nearest-frame resampling then repeats frames, the
// clips' stamps stay exact, and the SDN reads the repeats as 25 fps motion, with nothing said.
// Inputs: since, now  the counters at the window's start and now (a window of seconds);
//         options     the pipeline's options (frame_rate)
// Returns the reason, or "" while frames out do not outnumber frames in or fewer than 20 came.
std::string ClipRepeatReason(const ClipPipelineStats& since, const ClipPipelineStats& now,
                             const ClipPipelineOptions& options);

// Why a share of the frames out is thrown away with clips that holes broke, over a window: a
// 30 fps camera losing 4 frames in every 50 still made clips (no stall), but a quarter of the
// frames, and of the clips, went with the holes, under an OK.
// Inputs: since, now  the counters at the window's start and now;
//         options     the pipeline's options (num_frames, stride)
// Returns the reason, or "" while under a fifth of the frames clips would use were thrown away,
// or fewer than two clips' frames came out.
std::string ClipLossReason(const ClipPipelineStats& since, const ClipPipelineStats& now,
                           const ClipPipelineOptions& options);

// The ROS-free clip buffer: camera frames and anemometer readings in (each by stamp), labelled
// clips out. Frames go through FrameResampler (nearest frame by stamp onto a 25 fps grid),
// PreprocessClipFrame (crop, grey or colour, resize) and ClipAssembler (N_t frames every stride, broken at
// gaps); finished clips wait in a queue until their label is due (see label_delay), then get the
// WindLabeller's statistics over [last frame - label_window, last frame].
class ClipPipeline {
 public:
  explicit ClipPipeline(const ClipPipelineOptions& options);

  // Pushes one camera frame. A frame stamped more than gap_tolerance before the last one is held
  // until the next frame tells what it is: the start of a new timeline (a bag restarted or looped)
  // when the next one follows it within gap_tolerance, and then both go through as a time jump;
  // otherwise a lone stale stamp, dropped (frames_stale) without disturbing the stream.
  // Inputs:
  //   stamp     capture time [s] (header.stamp)
  //   image     rows x cols, type ClipSourceCvType(encoding); only read during the call
  //   encoding  its pixel layout
  //   now       the clock when it arrived [s] (ros::Time::now()), or kNoClock
  // Returns false when the frame was refused as stamped in the future (counted in frames_future).
  // Throws std::invalid_argument (roi does not fit, wrong type) after counting it as dropped.
  bool AddFrame(double stamp, const cv::Mat& image, ClipSourceEncoding encoding, double now = kNoClock);

  // Pushes one anemometer reading (any arrival order). Returns false when it was refused: stamped
  // more than max_future after `now` (counted in readings_future), or not finite.
  bool AddReading(const LabelReading& reading, double now = kNoClock);

  // Clips whose label is due (data time >= end + label_delay), oldest first; clips that were
  // waiting when camera time went back come first, labelled with the readings held then.
  std::vector<LabelledClip> TakeReady();

  // Every waiting clip, labelled with the readings held now (the stream ended or stalled); a frame
  // held back in time with nothing after it is dropped as stale.
  std::vector<LabelledClip> Flush();

  // Forgets everything, waiting clips included; counters are kept. (A jump back in camera time is
  // handled by AddFrame, which labels the waiting clips first.)
  void Reset();

  size_t pending() const { return pending_.size(); }
  const ClipPipelineStats& stats() const { return stats_; }
  const ClipPipelineOptions& options() const { return options_; }

 private:
  // The frame, preprocessed, through the resampler, the jump and gap rules and the assembler.
  void PushFrame(double stamp, const cv::Mat& processed);
  void BreakClip();  // assembler_.Break(), its discarded frames counted in stats_
  void Emit(const FrameResampler::Tick& tick, const cv::Mat& image);
  LabelledClip Release(AssembledClip clip);
  void TakeReading(const LabelReading& reading);  // into the labeller, counted late if it is
  // Whether a message stamped `stamp` that came at clock `now` is refused: past the clock by more
  // than max_future (counted in *future) or the previous pass's (counted in *previous).
  bool RefusedByClock(double stamp, double now, uint64_t* future, uint64_t* previous);

  ClipPipelineOptions options_;
  FrameResampler resampler_;
  ClipAssembler assembler_;
  WindLabeller labeller_;
  cv::Mat previous_;            // preprocessed previous camera frame (a tick may still pick it)
  SquareRoi roi_;               // resolved for the current source size
  int source_width_ = 0, source_height_ = 0;
  double data_time_;            // largest stamp seen on either stream [s]
  double last_frame_ = 0.0;     // stamp of the last accepted camera frame [s]
  ClockCourse clock_;  // the clock's course (RefusedByClock): where it was before it went back
  double released_end_;         // end of the last released clip [s]
  std::deque<AssembledClip> pending_;
  std::vector<LabelledClip> released_at_jump_;  // labelled at a time jump, not taken yet
  // Readings stamped before every window this timeline can still label, held until the next
  // frame says whose they are: a looped bag's first reading arrives before its first frame.
  // Readings held for the next frame (AddReading), at most kMaxHeldReadings (the oldest dropped,
  // counted late).
  static constexpr size_t kMaxHeldReadings = 4096;
  std::deque<LabelReading> held_;
  // A frame held until the next frame says whether time goes on from it. backward_: stamped back
  // in time, a new timeline (a looped bag) or a lone stale stamp.
  struct HeldFrame {
    double stamp;
    cv::Mat processed;
  };
  std::optional<HeldFrame> backward_;
  // A frame stamped more than gap_tolerance after the last, held until the next frame says whether
  // time goes on from it (a real hole, or a slow camera) or comes back (a lone frame stamped
  // ahead: taken, it made the next frames a jump back and reset the labeller's readings).
  std::optional<HeldFrame> forward_;
  ClipPipelineStats stats_;
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CLIP_PIPELINE_H_
