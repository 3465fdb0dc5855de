#include "learn/frame_cache.h"

#include <algorithm>
#include <stdexcept>

namespace clothwind::learn {

FrameCache::FrameCache(const std::vector<ClipInfo>& clips, int input_size, bool colour)
    : clips_(clips), input_size_(input_size), colour_(colour) {
  if (input_size < 1) throw std::invalid_argument("FrameCache: input size must be >= 1");
  slots_.reserve(clips.size());
  for (size_t i = 0; i < clips.size(); ++i) slots_.push_back(std::make_unique<Slot>());
}

bool FrameCache::Exact(const SampleOptions& options, const ClipInfo& clip, std::string* why) {
  // The judge reads the file frame's crop resized to its own side; from the cache it would read
  // the input square resized again, other pixels (a clip near the judge's margin could turn).
  if (options.flag_flies == FlagFlies::kAuto && options.fly_judge) {
    if (why) *why = "the fly judge (--flag-flies auto) reads the files' crops, not the cached squares";
    return false;
  }
  if (!options.augment) return true;  // evaluation: always the centre square
  for (double s : options.crop_scales) {
    if (s != 1.0) {
      if (why) *why = "training crop scale " + std::to_string(s) + " (the cache holds whole squares: use --crop-scales 1)";
      return false;
    }
  }
  if (clip.width != clip.height) {
    if (why) {
      *why = clip.name + ": frames are " + std::to_string(clip.width) + "x" + std::to_string(clip.height) +
             ", and a training crop slides along a non-square frame";
    }
    return false;
  }
  return true;
}

std::vector<cv::Mat> FrameCache::Frames(size_t index, int first, int count) {
  Slot& slot = *slots_.at(index);
  std::lock_guard<std::mutex> lock(slot.mutex);
  return FramesLocked(index, slot, first, count);
}

std::vector<cv::Mat> FrameCache::Flows(size_t index, int first, int count, int flow_side) {
  if (colour_) throw std::invalid_argument("FrameCache: flow asked of a colour cache (the flow is the grey frames')");
  if (flow_side == 0) flow_side = input_size_;
  int expected = 0;
  if (!flow_side_.compare_exchange_strong(expected, flow_side) && expected != flow_side) {
    throw std::invalid_argument("FrameCache: flow computed at " + std::to_string(flow_side) + " px asked of a cache holding " +
                                std::to_string(expected) + " px flow");
  }
  Slot& slot = *slots_.at(index);
  std::lock_guard<std::mutex> lock(slot.mutex);
  const std::vector<cv::Mat> frames = FramesLocked(index, slot, first, count);  // checks the range
  const ClipInfo& clip = clips_[index];
  const size_t plane = static_cast<size_t>(input_size_) * input_size_ * 2;
  if (slot.flow.empty()) {
    slot.flow.resize(static_cast<size_t>(clip.num_frames) * plane);
    slot.flow_loaded.assign(static_cast<size_t>(clip.num_frames), false);
    flow_bytes_ += slot.flow.size() * sizeof(int16_t);
  }
  // A flow finer than the input needs the files' frames; read them once for the whole window.
  const auto loaded = slot.flow_loaded.begin();
  const bool missing = std::find(loaded + first + 1, loaded + first + count, false) != loaded + first + count;
  const std::vector<cv::Mat> files =
      missing && flow_side != input_size_ ? LoadFrames(clip, first, count) : std::vector<cv::Mat>{};
  std::vector<cv::Mat> flows(frames.size() - 1);
  for (int t = first + 1; t < first + count; ++t) {
    cv::Mat held(input_size_, input_size_, CV_16SC2, slot.flow.data() + static_cast<size_t>(t) * plane);
    if (!slot.flow_loaded[static_cast<size_t>(t)]) {
      // At the input size the cached squares are what MakeSample would crop and resize.
      const std::vector<cv::Mat>& source = flow_side == input_size_ ? frames : files;
      const int i = t - first;
      const std::vector<cv::Mat> pair = {source[i - 1], source[i]};
      WindowFlows(pair, CentreSquare(pair[0].cols, pair[0].rows), flow_side, input_size_)[0].convertTo(
          held, CV_16SC2, kFlowSteps);
      slot.flow_loaded[static_cast<size_t>(t)] = true;
    }
    held.convertTo(flows[t - 1 - first], CV_32FC2, 1.0 / kFlowSteps);
  }
  return flows;
}

std::vector<cv::Mat> FrameCache::FramesLocked(size_t index, Slot& slot, int first, int count) {
  const ClipInfo& clip = clips_.at(index);
  if (first < 0 || count < 1 || first + count > clip.num_frames) {
    return LoadFrames(clip, first, count, colour_);  // throws the error a direct read gives
  }
  const int type = FrameType(colour_);
  const size_t plane = static_cast<size_t>(input_size_) * input_size_ * CV_MAT_CN(type);
  if (slot.pixels.empty()) {
    slot.pixels.resize(static_cast<size_t>(clip.num_frames) * plane);
    slot.loaded.assign(static_cast<size_t>(clip.num_frames), false);
    bytes_ += slot.pixels.size();
  }
  std::vector<cv::Mat> out;
  out.reserve(static_cast<size_t>(count));
  for (int t = first; t < first + count; ++t) {
    // A header over the clip's buffer: no copy, and valid as long as the cache.
    cv::Mat held(input_size_, input_size_, type, slot.pixels.data() + static_cast<size_t>(t) * plane);
    if (!slot.loaded[static_cast<size_t>(t)]) {
      const cv::Mat frame = LoadFrames(clip, t, 1, colour_)[0];
      // MakeSample's own crop and resize, written into `held` in place.
      ResizeCrop(frame, CentreSquare(frame.cols, frame.rows), input_size_, held);
      slot.loaded[static_cast<size_t>(t)] = true;
      ++frames_held_;
    }
    out.push_back(held);  // MakeSample only reads it
  }
  return out;
}

Sample LoadSample(FrameCache& cache, size_t index, const SampleOptions& options, uint64_t seed) {
  if (options.input_size != cache.input_size()) {
    throw std::invalid_argument("LoadSample: input size " + std::to_string(options.input_size) +
                                " but the frame cache holds " + std::to_string(cache.input_size()) + " px");
  }
  if (options.colour != cache.colour()) {
    throw std::invalid_argument(std::string("LoadSample: ") + (options.colour ? "colour" : "grey") +
                                " samples asked of a frame cache holding " + (cache.colour() ? "colour" : "grey") +
                                " frames");
  }
  // MakeSample's crop offsets are 0 on a whole square, and resizing S to S is a copy in OpenCV.
  return LoadSample(
      cache.clip(index), options, seed, [&cache, index](int first, int count) { return cache.Frames(index, first, count); },
      [&cache, index, &options](int first, int count) { return cache.Flows(index, first, count, options.flow_size); });
}

}  // namespace clothwind::learn
