#include "sensors/sequence_gaps.h"

#include <cmath>
#include <stdexcept>

namespace clothwind::sensors {

SequenceGaps::SequenceGaps(std::uint64_t max_gap, double recent_window)
    : max_gap_(max_gap), recent_window_(recent_window) {
  if (!(recent_window > 0) || !std::isfinite(recent_window)) {
    throw std::invalid_argument("SequenceGaps: recent_window must be a finite number of seconds > 0");
  }
}

std::uint64_t SequenceGaps::Good(std::uint64_t sequence, double now) {
  std::uint64_t gap = 0;
  // sequence > last_ first: last_ + 1 wraps to 0 at the top of the range.
  if (have_last_ && sequence > last_ && sequence - last_ - 1 > 0 && sequence - last_ - 1 <= max_gap_) {
    gap = sequence - last_ - 1;
    // Malformed items inside the gap arrived: they are not missing.
    for (auto it = malformed_since_good_.upper_bound(last_); it != malformed_since_good_.end() && *it < sequence; ++it) {
      --gap;
    }
    if (gap > 0) {
      missing_ += gap;
      recent_.emplace_back(now, gap);
    }
  }
  Trim(now);  // here too: a node that never asks (its model failing) must not grow the list
  malformed_since_good_.clear();
  last_ = sequence;
  have_last_ = true;
  return gap;
}

void SequenceGaps::Malformed(std::uint64_t sequence) {
  if (malformed_since_good_.size() < kMaxMalformed) malformed_since_good_.insert(sequence);
}

void SequenceGaps::Trim(double now) {
  while (!recent_.empty() && now - recent_.front().first > recent_window_) recent_.pop_front();
}

std::uint64_t SequenceGaps::RecentMissing(double now) {
  Trim(now);
  std::uint64_t missing = 0;
  for (const auto& gap : recent_) missing += gap.second;
  return missing;
}

}  // namespace clothwind::sensors
