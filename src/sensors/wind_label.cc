#include "sensors/wind_label.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

namespace clothwind::sensors {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Accumulates the label statistics; Welford's update keeps the variance exact for long windows
// of nearly equal speeds.
struct Accumulator {
  uint32_t count = 0;
  double mean = 0.0, m2 = 0.0;
  double sin_sum = 0.0, cos_sum = 0.0;
  uint32_t directions = 0;
  double first = kNaN, last = kNaN;
  std::map<std::pair<std::string, std::string>, uint32_t> sources;
  uint32_t relative = 0;

  void Add(const LabelReading& r) {
    ++count;
    ++sources[{r.source, r.frame_id}];
    if (r.relative) ++relative;
    const double delta = r.speed - mean;
    mean += delta / count;
    m2 += delta * (r.speed - mean);
    if (std::isfinite(r.direction)) {
      sin_sum += std::sin(r.direction);
      cos_sum += std::cos(r.direction);
      ++directions;
    }
    if (!(r.stamp >= first)) first = r.stamp;  // also replaces NaN
    if (!(r.stamp <= last)) last = r.stamp;
  }

  WindLabel Finish(double end, double window) const {
    WindLabel label;
    label.window = window;
    label.end = end;
    label.count = count;
    label.mean = count ? mean : kNaN;
    label.std = count ? std::sqrt(std::max(0.0, m2 / count)) : kNaN;
    label.direction_mean =
        (directions && (sin_sum != 0.0 || cos_sum != 0.0)) ? std::atan2(sin_sum, cos_sum) : kNaN;
    label.first_stamp = first;
    label.last_stamp = last;
    for (const auto& [key, n] : sources) label.sources.push_back({key.first, key.second, n});
    label.relative_count = relative;
    return label;
  }
};

bool Usable(const LabelReading& r) { return std::isfinite(r.stamp) && std::isfinite(r.speed); }
}  // namespace

WindLabel ComputeWindLabel(const std::vector<LabelReading>& readings, double end, double window) {
  Accumulator acc;
  for (const auto& r : readings)
    if (Usable(r) && r.stamp >= end - window && r.stamp <= end) acc.Add(r);
  return acc.Finish(end, window);
}

WindLabeller::WindLabeller(double window)
    : window_(window), newest_(-std::numeric_limits<double>::infinity()) {
  if (!(window > 0.0))
    throw std::invalid_argument("label window must be > 0 s, got " + std::to_string(window));
}

bool WindLabeller::Add(const LabelReading& reading) {
  if (!Usable(reading)) return false;
  // Nearly always appended; a late reading is inserted at its stamp.
  auto it = std::upper_bound(readings_.begin(), readings_.end(), reading.stamp,
                             [](double s, const LabelReading& r) { return s < r.stamp; });
  readings_.insert(it, reading);
  newest_ = std::max(newest_, reading.stamp);
  return true;
}

WindLabel WindLabeller::Label(double end) const {
  Accumulator acc;
  auto it = std::lower_bound(readings_.begin(), readings_.end(), end - window_,
                             [](const LabelReading& r, double s) { return r.stamp < s; });
  for (; it != readings_.end() && it->stamp <= end; ++it) acc.Add(*it);
  return acc.Finish(end, window_);
}

void WindLabeller::Prune(double before) {
  while (!readings_.empty() && readings_.front().stamp < before) readings_.pop_front();
}

}  // namespace clothwind::sensors
