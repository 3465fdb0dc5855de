#include "sensors/clip_assembler.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace clothwind::sensors {

ClipAssembler::ClipAssembler(int num_frames, int stride) : num_frames_(num_frames), stride_(stride) {
  if (num_frames < 1) throw std::invalid_argument("num_frames must be >= 1, got " + std::to_string(num_frames));
  if (stride < 1) throw std::invalid_argument("stride must be >= 1, got " + std::to_string(stride));
}

void ClipAssembler::Break() {
  if (since_restart_ > 0) {
    ++breaks_;
    // Only the frames the next clip would have held: with a stride wider than num_frames, those
    // between two clips belong to none, and counting them read a stream whose holes cost no clip
    // frame as one that lost a third of its frames (clip_buffer's WARN, ClipLossReason).
    const int64_t next_end = since_restart_ < num_frames_
                                 ? num_frames_
                                 : num_frames_ + ((since_restart_ - num_frames_) / stride_ + 1) * stride_;
    const int64_t in_next_clip = std::max<int64_t>(0, since_restart_ - (next_end - num_frames_));
    frames_discarded_ += static_cast<uint64_t>(std::min(since_emit_, in_next_clip));
  }
  window_.clear();
  since_restart_ = 0;
  since_emit_ = 0;
}

std::optional<AssembledClip> ClipAssembler::Add(ClipFrame frame) {
  if (!window_.empty() && frame.tick != window_.back().tick + 1) Break();
  window_.push_back(std::move(frame));
  if (static_cast<int>(window_.size()) > num_frames_) window_.pop_front();
  ++since_restart_;
  since_emit_ = std::min<int64_t>(since_emit_ + 1, num_frames_);
  if (since_restart_ < num_frames_ || (since_restart_ - num_frames_) % stride_ != 0) return std::nullopt;
  AssembledClip clip;
  clip.sequence = next_sequence_++;
  clip.frames.assign(window_.begin(), window_.end());
  since_emit_ = 0;
  return clip;
}

}  // namespace clothwind::sensors
