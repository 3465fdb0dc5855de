// Decoded frames kept in memory between epochs, so that a dataset larger than the page cache is
// read from disk once rather than every epoch (flagsim-e5's 9.6 GB of JPEGs: 65 min for 20
// epochs on 2 cores, disk-bound; docs/sdn.md). The issue allows caching what precedes the
// learnable layers provided the augmentation stays the seed's; this cache holds each frame's
// centre square resized to the input side, which is exactly what MakeSample would crop and
// resize whenever its crop is the whole square (evaluation; training with --crop-scales 1 on
// square frames). Flips, the temporal offset and per-clip normalisation still run per sample.
#ifndef CLOTHWIND_LEARN_FRAME_CACHE_H_
#define CLOTHWIND_LEARN_FRAME_CACHE_H_

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "learn/dataset.h"

namespace clothwind::learn {

class FrameCache {
 public:
  // Inputs:
  //   clips       the examples it serves, addressed by their index in this vector (kept by
  //               reference: it must outlive the cache)
  //   input_size  S, the side the frames are resized to [px]
  //   colour      hold LoadFrames' colour frames (YCrCb, 3 bytes a pixel) instead of grey ones
  FrameCache(const std::vector<ClipInfo>& clips, int input_size, bool colour = false);

  // Whether LoadSample(cache, ...) with `options` gives the same samples as LoadSample(clip, ...):
  // true when the sample's crop is always the centre square, i.e. evaluation, or augmentation
  // whose crop scales are all 1 on a square frame (a non-square frame's training crop slides).
  // When false, `why` says which option or frame size breaks it.
  static bool Exact(const SampleOptions& options, const ClipInfo& clip, std::string* why);

  // Frames first..first+count-1 of clip `index` as S x S CV_8UC1 images (CV_8UC3 YCrCb for a
  // colour cache), decoding and resizing
  // the ones not yet held. Safe to call from several threads.
  // Throws what LoadFrames throws for a missing or malformed frame.
  std::vector<cv::Mat> Frames(size_t index, int first, int count);

  // WindowFlows of frames first..first+count-1 of clip `index` (count - 1 CV_32FC2 images of
  // S x S) with the flow computed at flow_side (0: S), computing and keeping (16 bits per
  // component) the flows not yet held. Equal to WindowFlows(files' frames, centre square,
  // flow_side, S). A cache holds one flow_side: another throws std::invalid_argument. Safe to call
  // from several threads. A colour cache has no flows (std::invalid_argument).
  std::vector<cv::Mat> Flows(size_t index, int first, int count, int flow_side = 0);

  const ClipInfo& clip(size_t index) const { return clips_.at(index); }
  int input_size() const { return input_size_; }
  bool colour() const { return colour_; }
  size_t size() const { return slots_.size(); }
  // Pixel bytes allocated now: num_frames x S^2 (x 3 in colour) for every clip read so far (at most
  // clips x frames x S^2), and how many frames of them have been decoded.
  size_t bytes() const { return bytes_.load(); }
  size_t frames_held() const { return frames_held_.load(); }
  // Flow bytes allocated now: num_frames x S^2 x 4 for every clip whose flow was read.
  size_t flow_bytes() const { return flow_bytes_.load(); }

 private:
  // One allocation per clip, not one per frame: 4 KB frames kept between the JPEG decoder's
  // short-lived buffers fragmented the heap: 13 GB resident early in flagsim-e5's second epoch,
  // whose frames are 4.7 GB in all.
  struct Slot {
    std::mutex mutex;
    std::vector<uint8_t> pixels;  // num_frames x S x S (x 3 in colour), allocated at the first read
    std::vector<bool> loaded;     // per frame
    std::vector<int16_t> flow;    // num_frames x S x S x 2: frame t's flow from frame t - 1 (t >= 1)
    std::vector<bool> flow_loaded;
  };
  // Frames() with the slot's mutex already held.
  std::vector<cv::Mat> FramesLocked(size_t index, Slot& slot, int first, int count);
  const std::vector<ClipInfo>& clips_;
  int input_size_;
  bool colour_;
  std::vector<std::unique_ptr<Slot>> slots_;
  std::atomic<size_t> bytes_{0};
  std::atomic<size_t> frames_held_{0};
  std::atomic<size_t> flow_bytes_{0};
  std::atomic<int> flow_side_{0};  // the flow side held (0: none yet)
};

// LoadSample for example `index` of the cache's clips, its frames from the cache: pixels, window,
// flip and speed equal to LoadSample(clips[index], options, seed)'s whenever FrameCache::Exact
// holds (sample.crop is then the whole S x S cached square, not the square in the file's pixels).
// Throws std::invalid_argument when options.input_size is not the cache's.
// With options.flow, the flows come from the cache as well (FrameCache::Flows).
Sample LoadSample(FrameCache& cache, size_t index, const SampleOptions& options, uint64_t seed);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FRAME_CACHE_H_
