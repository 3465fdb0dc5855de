#include "sensors/clip_pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace clothwind::sensors {
namespace {
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
}

void ValidateClipPipelineOptions(const ClipPipelineOptions& o) {
  auto fail = [](const std::string& name, const std::string& expected, double got) {
    std::ostringstream s;
    s << name << " must be " << expected << ", got " << got;
    throw std::invalid_argument(s.str());
  };
  if (!(std::isfinite(o.frame_rate) && o.frame_rate > 0.0)) fail("frame_rate", "a finite rate > 0 Hz", o.frame_rate);
  if (!(std::isfinite(o.gap_tolerance) && o.gap_tolerance > 0.0))
    fail("gap_tolerance", "a finite interval > 0 s", o.gap_tolerance);
  if (o.num_frames < 1 || o.num_frames > kMaxClipFrames)
    fail("num_frames", "in 1.." + std::to_string(kMaxClipFrames), o.num_frames);
  if (o.stride < 1) fail("stride", ">= 1", o.stride);
  if (o.size < kMinClipSide || o.size > kMaxClipSide)
    fail("size", "in " + std::to_string(kMinClipSide) + ".." + std::to_string(kMaxClipSide) + " px", o.size);
  if (o.roi.size < 0 || o.roi.x < 0 || o.roi.y < 0) fail("roi", "[x >= 0, y >= 0, size >= 0] in source pixels",
                                                         std::min({o.roi.x, o.roi.y, o.roi.size}));
  if (!(std::isfinite(o.label_window) && o.label_window > 0.0))
    fail("label_window", "a finite window > 0 s", o.label_window);
  if (!(std::isfinite(o.label_delay) && o.label_delay >= 0.0))
    fail("label_delay", "a finite delay >= 0 s", o.label_delay);
  if (!(o.max_future >= 0.0)) fail("max_future", ">= 0 s (inf: stamps not checked)", o.max_future);
}

ClipPipeline::ClipPipeline(const ClipPipelineOptions& options)
    : options_((ValidateClipPipelineOptions(options), options)),
      resampler_(options.frame_rate, options.gap_tolerance),
      assembler_(options.num_frames, options.stride),
      labeller_(options.label_window),
      data_time_(kNegInf),
      released_end_(kNegInf) {
}

bool ClipPipeline::RefusedByClock(double stamp, double now, uint64_t* future, uint64_t* previous) {
  clock_.Note(now);  // kNoClock (inf) is ignored
  if (!(stamp > now + options_.max_future)) return false;
  if (clock_.IsPreviousPass(stamp, options_.max_future)) {
    ++*previous;
    return true;
  }
  ++*future;
  stats_.last_future_lead = stamp - now;
  return true;
}

void ClipPipeline::Reset() {
  resampler_.Reset();
  BreakClip();
  previous_.release();
  pending_.clear();
  released_at_jump_.clear();
  held_.clear();
  backward_.reset();
  forward_.reset();
  labeller_ = WindLabeller(options_.label_window);
  data_time_ = kNegInf;
  released_end_ = kNegInf;
  last_frame_ = 0.0;
}

bool ClipPipeline::AddFrame(double stamp, const cv::Mat& image, ClipSourceEncoding encoding, double now) {
  ++stats_.frames_in;
  if (RefusedByClock(stamp, now, &stats_.frames_future, &stats_.frames_previous_pass)) {
    ++stats_.frames_dropped;
    return false;
  }
  cv::Mat processed;
  try {
    if (image.cols != source_width_ || image.rows != source_height_) {
      roi_ = ResolveRoi(options_.roi, image.cols, image.rows);
      source_width_ = image.cols;
      source_height_ = image.rows;
      resampler_.Reset();  // a new image size is a new stream
      BreakClip();
    }
    processed = PreprocessClipFrame(image, encoding, roi_, options_.size, options_.colour);
  } catch (...) {
    ++stats_.frames_dropped;
    source_width_ = source_height_ = 0;  // re-resolve the roi on the next frame
    throw;
  }
  // A frame back in time waits for the next: one that follows it within gap_tolerance starts a
  // new timeline there (a bag looped or restarted, with or without --clock); any other means it
  // was a lone stale stamp, which restarted the labeller and released the waiting clips early.
  // Strictly after: the same stale frame delivered twice confirmed itself as a new timeline.
  if (backward_) {
    HeldFrame held = std::move(*backward_);
    backward_.reset();
    if (std::isfinite(stamp) && stamp > held.stamp && stamp - held.stamp <= options_.gap_tolerance) {
      PushFrame(held.stamp, held.processed);
    } else {
      ++stats_.frames_stale;
      ++stats_.frames_dropped;
    }
  }
  // A frame after a hole waits for the next likewise: time going on from it confirms it; time
  // coming back before it (one frame stamped 0.15 s ahead at 30 fps) drops it as stale.
  if (forward_) {
    HeldFrame held = std::move(*forward_);
    forward_.reset();
    if (std::isfinite(stamp) && stamp > held.stamp) {
      PushFrame(held.stamp, held.processed);
    } else {
      ++stats_.frames_stale;
      ++stats_.frames_dropped;
    }
  }
  if (last_frame_ > 0 && std::isfinite(stamp) && stamp < last_frame_ - options_.gap_tolerance) {
    backward_ = HeldFrame{stamp, processed};
    return true;
  }
  if (last_frame_ > 0 && std::isfinite(stamp) && stamp - last_frame_ > options_.gap_tolerance) {
    forward_ = HeldFrame{stamp, processed};
    return true;
  }
  PushFrame(stamp, processed);
  return true;
}

void ClipPipeline::PushFrame(double stamp, const cv::Mat& processed) {
  // Decided here, not only by the resampler: a new image size resets it, and the frame back in
  // time was then its first ("restarted"), so a restart at another size kept the old timeline's
  // labeller and data time, and every later clip went out at once, unlabelled.
  const bool went_back = last_frame_ > 0 && stamp < last_frame_ - options_.gap_tolerance;
  const FrameResampler::Result r = resampler_.Push(stamp);
  if (r.dropped) {
    ++stats_.frames_dropped;
    return;
  }
  if (r.gap) {
    ++stats_.gaps;
    stats_.last_gap = stamp - last_frame_;
    BreakClip();
  }
  if (r.restarted) BreakClip();
  if (r.jumped_back || went_back) {
    // Time went back (a bag restarted or looped): the old timeline's readings must not label the
    // new one's clips. Its waiting clips are labelled now with what it has (as Flush does at the
    // end of a stream) rather than lost, and its readings forgotten.
    ++stats_.time_jumps;
    stats_.clips_at_jumps += pending_.size();
    for (auto& clip : pending_) released_at_jump_.push_back(Release(std::move(clip)));
    pending_.clear();
    labeller_ = WindLabeller(options_.label_window);
    data_time_ = kNegInf;
    released_end_ = kNegInf;
  }
  // Held readings belong to this frame's timeline: the new one after a jump, else late ones.
  for (const LabelReading& reading : held_) TakeReading(reading);
  held_.clear();
  for (const auto& tick : r.ticks) Emit(tick, tick.from_previous ? previous_ : processed);
  previous_ = processed;
  last_frame_ = stamp;
  data_time_ = std::max(data_time_, stamp);
}

void ClipPipeline::BreakClip() {
  assembler_.Break();
  stats_.frames_discarded = assembler_.frames_discarded();
}

void ClipPipeline::Emit(const FrameResampler::Tick& tick, const cv::Mat& image) {
  ++stats_.frames_out;
  auto clip = assembler_.Add({tick.index, tick.stamp, tick.source_stamp, image});
  if (clip) {
    ++stats_.clips_made;
    pending_.push_back(std::move(*clip));
  }
}

bool ClipPipeline::AddReading(const LabelReading& reading, double now) {
  if (RefusedByClock(reading.stamp, now, &stats_.readings_future, &stats_.readings_previous_pass)) return false;
  if (!(std::isfinite(reading.stamp) && std::isfinite(reading.speed))) return false;
  ++stats_.readings_in;
  // Before every window still open (the waiting clips' and the one being assembled), with a
  // second to spare: no use to this timeline, and maybe the first of the next one (a bag that
  // looped). Such a reading labelled the old timeline's last clips at the jump and was then
  // forgotten with them; it is held until the next frame tells.
  const double open_from =
      (pending_.empty() ? last_frame_ : std::min(last_frame_, pending_.front().frames.back().stamp)) -
      options_.label_window - 1.0;
  // Also one later than label_delay and a second behind the data: a bag shorter than the label
  // window looped, its first reading inside every window still open, labelled the old timeline's
  // last clips and was forgotten at the jump. Held, a late reading of this timeline only waits for
  // the next frame (which takes it before the data moves on).
  const double behind = data_time_ - options_.label_delay - 1.0;
  if (last_frame_ > 0 && (reading.stamp < open_from || reading.stamp < behind)) {
    // Bounded: frames stopped while a second instrument, its clock behind, kept sending.
    if (held_.size() >= kMaxHeldReadings) {
      held_.pop_front();
      ++stats_.readings_late;
    }
    held_.push_back(reading);
    return true;
  }
  TakeReading(reading);
  return true;
}

void ClipPipeline::TakeReading(const LabelReading& reading) {
  labeller_.Add(reading);
  if (reading.stamp <= released_end_) ++stats_.readings_late;
  data_time_ = std::max(data_time_, reading.stamp);
}

LabelledClip ClipPipeline::Release(AssembledClip clip) {
  LabelledClip out;
  const double end = clip.frames.back().stamp;
  out.label = labeller_.Label(end);
  out.clip = std::move(clip);
  out.roi = roi_;
  out.source_width = source_width_;
  out.source_height = source_height_;
  out.frame_rate = options_.frame_rate;
  ++stats_.clips_released;
  if (out.label.count == 0) {
    ++stats_.clips_unlabelled;
    ++stats_.unlabelled_run;
  } else {
    stats_.unlabelled_run = 0;
  }
  released_end_ = std::max(released_end_, end);
  return out;
}

std::vector<LabelledClip> ClipPipeline::TakeReady() {
  std::vector<LabelledClip> ready = std::move(released_at_jump_);
  released_at_jump_.clear();
  while (!pending_.empty() && data_time_ >= pending_.front().frames.back().stamp + options_.label_delay) {
    ready.push_back(Release(std::move(pending_.front())));
    pending_.pop_front();
  }
  // Readings older than every window still to come are no longer needed.
  if (pending_.empty()) {
    labeller_.Prune(data_time_ - options_.label_window - options_.label_delay -
                    options_.num_frames / options_.frame_rate - 10.0);
  } else {
    labeller_.Prune(pending_.front().frames.back().stamp - options_.label_window);
  }
  return ready;
}

std::vector<LabelledClip> ClipPipeline::Flush() {
  // A frame back in time with nothing after it (the stream ended or stalled) is one frame: it
  // is dropped as stale, and the frame after the stall starts afresh.
  if (backward_) {
    backward_.reset();
    ++stats_.frames_stale;
    ++stats_.frames_dropped;
  }
  // A frame after a hole with nothing after it: time did go on to it, so it is taken.
  if (forward_) {
    PushFrame(forward_->stamp, forward_->processed);
    forward_.reset();
  }
  // Readings held for the next frame belong to this timeline when none comes.
  for (const LabelReading& reading : held_) TakeReading(reading);
  held_.clear();
  std::vector<LabelledClip> ready = std::move(released_at_jump_);
  released_at_jump_.clear();
  while (!pending_.empty()) {
    ready.push_back(Release(std::move(pending_.front())));
    pending_.pop_front();
  }
  return ready;
}

std::string ClipLossReason(const ClipPipelineStats& since, const ClipPipelineStats& now,
                           const ClipPipelineOptions& options) {
  const uint64_t out = now.frames_out - since.frames_out;
  const uint64_t lost = now.frames_discarded - since.frames_discarded;
  const uint64_t gaps = now.gaps - since.gaps;
  if (out < 2 * static_cast<uint64_t>(options.num_frames) || lost == 0) return "";
  // The frames clips would use: all of them with a stride of num_frames or less, a share with a
  // wider stride (the frames between sparse clips are not lost, only unused).
  const double used = static_cast<double>(out) * options.num_frames / std::max(options.stride, options.num_frames);
  if (5.0 * static_cast<double>(lost) <= used) return "";
  char text[256];
  std::snprintf(text, sizeof text,
                "%llu of the last %llu frames out were thrown away with the clips %llu holes longer than "
                "gap_tolerance %.3g s broke (frames lost in bursts: a USB camera, or a bag recorded with drops?)",
                static_cast<unsigned long long>(lost), static_cast<unsigned long long>(out),
                static_cast<unsigned long long>(gaps), options.gap_tolerance);
  return text;
}

std::string ClipRepeatReason(const ClipPipelineStats& since, const ClipPipelineStats& now,
                             const ClipPipelineOptions& options) {
  const uint64_t in = now.frames_in - since.frames_in, out = now.frames_out - since.frames_out;
  if (in < 20 || out * 10 <= in * 11) return "";
  char text[256];
  std::snprintf(text, sizeof text,
                "the camera gives about %.0f frames for every %.0f the clips need (%llu in, %llu out): a camera slower "
                "than %.3g fps, whose frames repeat in the clips",
                options.frame_rate * static_cast<double>(in) / static_cast<double>(out), options.frame_rate,
                static_cast<unsigned long long>(in), static_cast<unsigned long long>(out), options.frame_rate);
  return text;
}

std::string ClipStallReason(const ClipPipelineStats& since, const ClipPipelineStats& now,
                            const ClipPipelineOptions& options) {
  const uint64_t in = now.frames_in - since.frames_in;
  if (now.clips_made != since.clips_made || in < 2 * static_cast<uint64_t>(options.num_frames)) return "";
  // Frames refused as from the future have their own WARN; the rest of the drops are stamps that
  // do not increase (or bad images, which are errors of their own).
  const uint64_t not_after = (now.frames_dropped - since.frames_dropped) - (now.frames_future - since.frames_future) -
                             (now.frames_previous_pass - since.frames_previous_pass);
  const uint64_t gaps = now.gaps - since.gaps;
  char text[320];
  if (2 * not_after >= in) {
    std::snprintf(text, sizeof text,
                  "no clip from the last %llu camera frames: %llu were not stamped after the frame before "
                  "(header.stamp 0, or a camera clock that stands still?)",
                  static_cast<unsigned long long>(in), static_cast<unsigned long long>(not_after));
    return text;
  }
  if (2 * gaps >= in) {
    std::snprintf(text, sizeof text,
                  "no clip from the last %llu camera frames: %llu intervals were longer than gap_tolerance %.3g s "
                  "(last %.3g s; a camera below %.3g fps?)",
                  static_cast<unsigned long long>(in), static_cast<unsigned long long>(gaps), options.gap_tolerance,
                  now.last_gap, 1.0 / options.gap_tolerance);
    return text;
  }
  // Holes too rare for the test above but too frequent for a clip: a 30 fps stream losing 3
  // frames about once a second (a bag recorded with drops, a USB camera losing bursts) never
  // has the 29 periods unbroken that a clip needs, and the node said OK "making clips".
  // Only past a clip's frames plus its stride of output frames: with ~stride over num_frames (a
  // clip every 6 s) no clip for 2 clips' worth of frames is the stride, not the holes.
  const uint64_t out = now.frames_out - since.frames_out;
  const uint64_t clip_period = static_cast<uint64_t>(options.num_frames + std::max(options.stride, options.num_frames));
  if (gaps > 0 && out >= clip_period) {
    std::snprintf(text, sizeof text,
                  "no clip from the last %llu camera frames: %llu holes longer than gap_tolerance %.3g s (last %.3g s) "
                  "broke every clip before its %d frames (frames lost in bursts: a USB camera, or a bag recorded "
                  "with drops?)",
                  static_cast<unsigned long long>(in), static_cast<unsigned long long>(gaps), options.gap_tolerance,
                  now.last_gap, options.num_frames);
    return text;
  }
  return "";
}

}  // namespace clothwind::sensors
