#include "sensors/clip_pipeline.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace clothwind::sensors {
namespace {
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
}

ClipPipeline::ClipPipeline(const ClipPipelineOptions& options)
    : options_(options),
      resampler_(options.frame_rate, options.gap_tolerance),
      assembler_(options.num_frames, options.stride),
      labeller_(options.label_window),
      data_time_(kNegInf),
      released_end_(kNegInf) {
  if (options.size <= 0) throw std::invalid_argument("size must be > 0 px, got " + std::to_string(options.size));
  if (!(options.label_delay >= 0.0))
    throw std::invalid_argument("label_delay must be >= 0 s, got " + std::to_string(options.label_delay));
}

void ClipPipeline::Reset() {
  resampler_.Reset();
  assembler_.Break();
  previous_.release();
  pending_.clear();
  labeller_ = WindLabeller(options_.label_window);
  data_time_ = kNegInf;
  released_end_ = kNegInf;
}

void ClipPipeline::AddFrame(double stamp, const cv::Mat& image, ClipSourceEncoding encoding) {
  ++stats_.frames_in;
  cv::Mat processed;
  try {
    if (image.cols != source_width_ || image.rows != source_height_) {
      roi_ = ResolveRoi(options_.roi, image.cols, image.rows);
      source_width_ = image.cols;
      source_height_ = image.rows;
      resampler_.Reset();  // a new image size is a new stream
      assembler_.Break();
    }
    processed = PreprocessClipFrame(image, encoding, roi_, options_.size, options_.colour);
  } catch (...) {
    ++stats_.frames_dropped;
    source_width_ = source_height_ = 0;  // re-resolve the roi on the next frame
    throw;
  }
  const FrameResampler::Result r = resampler_.Push(stamp);
  if (r.dropped) {
    ++stats_.frames_dropped;
    return;
  }
  if (r.gap) {
    ++stats_.gaps;
    stats_.last_gap = stamp - last_frame_;
    assembler_.Break();
  }
  if (r.restarted) assembler_.Break();
  if (r.jumped_back) {
    // Time went back (a bag restarted): clips and readings of the old timeline are meaningless.
    pending_.clear();
    labeller_ = WindLabeller(options_.label_window);
    data_time_ = kNegInf;
    released_end_ = kNegInf;
  }
  for (const auto& tick : r.ticks) Emit(tick, tick.from_previous ? previous_ : processed);
  previous_ = processed;
  last_frame_ = stamp;
  data_time_ = std::max(data_time_, stamp);
}

void ClipPipeline::Emit(const FrameResampler::Tick& tick, const cv::Mat& image) {
  ++stats_.frames_out;
  auto clip = assembler_.Add({tick.index, tick.stamp, tick.source_stamp, image});
  if (clip) {
    ++stats_.clips_made;
    pending_.push_back(std::move(*clip));
  }
}

void ClipPipeline::AddReading(const LabelReading& reading) {
  if (!labeller_.Add(reading)) return;
  ++stats_.readings_in;
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
  if (out.label.count == 0) ++stats_.clips_unlabelled;
  released_end_ = std::max(released_end_, end);
  return out;
}

std::vector<LabelledClip> ClipPipeline::TakeReady() {
  std::vector<LabelledClip> ready;
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
  std::vector<LabelledClip> ready;
  while (!pending_.empty()) {
    ready.push_back(Release(std::move(pending_.front())));
    pending_.pop_front();
  }
  return ready;
}

}  // namespace clothwind::sensors
