// Counts the items missing from a numbered stream (sdn_node: clips, numbered by clip_buffer),
// from the numbers of those that arrive. ROS-free.
//
// A gap between two good items counts what is missing between them, less the malformed items that
// arrived inside it (they came; they are counted elsewhere). A malformed item's own number does not
// move the sequence: one stray number (1000 between clips 1 and 2) would otherwise read as 998
// missing. A number at or below the last good one (a restarted buffer or bag) starts the count
// again, as does a jump of more than `max_gap` numbers (a new numbering: 2^63 then 0, 1, 2 read as
// 9.2e18 missing).
#ifndef CLOTHWIND_SENSORS_SEQUENCE_GAPS_H_
#define CLOTHWIND_SENSORS_SEQUENCE_GAPS_H_

#include <cstddef>
#include <cstdint>
#include <deque>
#include <set>
#include <utility>

namespace clothwind::sensors {

class SequenceGaps {
 public:
  // max_gap: the largest jump read as losses (default: a day of clips at 25 fps, stride 1).
  // recent_window [s] > 0: RecentMissing's span. Throws std::invalid_argument otherwise.
  explicit SequenceGaps(std::uint64_t max_gap = 25ull * 86400, double recent_window = 30.0);

  // A good item numbered `sequence` arrived at time `now` [s] (any monotonic clock: RecentMissing
  // reads the same one). Returns the items missing since the last good one (0 for the first).
  std::uint64_t Good(std::uint64_t sequence, double now);
  // A malformed item numbered `sequence` arrived. At most kMaxMalformed are remembered between
  // two good ones (a stream of nothing but malformed items would grow the set for ever); beyond
  // them, a later gap may count some of them as missing.
  void Malformed(std::uint64_t sequence);

  // All items missing so far.
  std::uint64_t Missing() const { return missing_; }
  // Those found missing in [now - recent_window, now]; forgets older gaps.
  std::uint64_t RecentMissing(double now);

  static constexpr std::size_t kMaxMalformed = 4096;

 private:
  void Trim(double now);  // forgets gaps found before now - recent_window

  std::uint64_t max_gap_;
  double recent_window_;
  bool have_last_ = false;
  std::uint64_t last_ = 0, missing_ = 0;
  std::set<std::uint64_t> malformed_since_good_;
  std::deque<std::pair<double, std::uint64_t>> recent_;  // (time [s], items missing) of each gap
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_SEQUENCE_GAPS_H_
