#ifndef CLOTHWIND_SENSORS_WIND_LABEL_H_
#define CLOTHWIND_SENSORS_WIND_LABEL_H_

#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

namespace clothwind::sensors {

// One anemometer reading as the labeller needs it (a subset of clothwind/WindMeasurement).
struct LabelReading {
  double stamp = 0.0;      // when the reading was taken [s] (header.stamp)
  double speed = 0.0;      // [m/s]; NaN readings are ignored
  double direction = 0.0;  // [rad], WindMeasurement convention; NaN when the instrument gives none
  // Which instrument measured it: the protocol (WindMeasurement.source, e.g. "nmea_mwv") and the
  // instrument's frame (header.frame_id); and whether it is apparent (relative) wind.
  std::string source{};
  std::string frame_id{};
  bool relative = false;
};

// The readings of one instrument (source and frame) among a label's.
struct WindLabelSource {
  std::string source;
  std::string frame_id;
  uint32_t count = 0;
  bool operator==(const WindLabelSource& o) const {
    return source == o.source && frame_id == o.frame_id && count == o.count;
  }
};

// The anemometer label of a clip: statistics of the readings stamped in [end - window, end].
struct WindLabel {
  double window = 0.0;          // [s]
  double end = 0.0;             // window end = stamp of the clip's last frame [s]
  double mean = 0.0;            // [m/s]; NaN when count == 0
  double std = 0.0;             // population standard deviation [m/s]; NaN when count == 0
  uint32_t count = 0;           // readings in the window
  double direction_mean = 0.0;  // circular mean [rad] in (-pi, pi]; NaN when no reading has one
  double first_stamp = 0.0;     // stamp of the earliest / latest reading in the window [s]; NaN if none
  double last_stamp = 0.0;
  // The instruments whose readings were counted, sorted by (source, frame_id), and how many of
  // the counted readings were apparent (relative) wind: a label that mixes two anemometers, or
  // relative with true wind, says so.
  std::vector<WindLabelSource> sources;
  uint32_t relative_count = 0;
};

// Computes the label over [end - window, end] (both ends included) from readings in any order.
// Inputs:
//   readings  #R readings (stamps [s], speeds [m/s], directions [rad])
//   end       window end [s]
//   window    window length [s] > 0 (60, as the paper's "average over the last minute")
// Returns mean, population std and count of the finite speeds; the circular mean of the finite
// directions, atan2(sum sin, sum cos) (NaN when there are none or they cancel exactly).
WindLabel ComputeWindLabel(const std::vector<LabelReading>& readings, double end, double window);

// Keeps anemometer readings ordered by STAMP (not arrival), so a reading that arrives late but
// is stamped inside a window still counts, and answers label queries over any recent window.
class WindLabeller {
 public:
  // window: label window [s] > 0.
  explicit WindLabeller(double window);

  // Adds one reading; readings may arrive out of order. Readings with a non-finite speed or stamp
  // are ignored (returns false).
  bool Add(const LabelReading& reading);

  // Label over [end - window, end] from the readings held now.
  WindLabel Label(double end) const;

  // Forgets readings stamped before `before` [s] (older than any window still to be labelled).
  void Prune(double before);

  // Largest stamp added so far [s] (-inf before the first reading).
  double newest_stamp() const { return newest_; }
  size_t size() const { return readings_.size(); }
  double window() const { return window_; }

 private:
  double window_;
  double newest_;
  std::deque<LabelReading> readings_;  // sorted by stamp
};

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_WIND_LABEL_H_
