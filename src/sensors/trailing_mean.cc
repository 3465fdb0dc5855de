#include "sensors/trailing_mean.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace clothwind::sensors {
namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

TrailingMean::TrailingMean(double window) : window_(window) {
  if (!(window > 0) || !std::isfinite(window)) throw std::invalid_argument("TrailingMean: window must be > 0 s");
}

void TrailingMean::Add(double t, double value, double std, std::uint64_t tag) {
  if (!entries_.empty() && t < entries_.back().t) {
    entries_.clear();
    ++restarts_;
  }
  const bool finite = std::isfinite(value);
  entries_.push_back({t, finite ? value : kNaN, std::isfinite(std) ? std * std : kNaN, tag});
  while (!entries_.empty() && entries_.front().t <= t - window_) entries_.pop_front();
  // Sums over the window recomputed from its entries (a minute holds ~50 clips): running sums
  // kept by adding and subtracting lose a small value beside a huge one for good (one outlier of
  // 1e17 left the mean of a stream of 4.0 at 3.2 after it had left the window).
  count_ = no_std_ = 0;
  sum_ = sum_var_ = 0.0;
  for (const Entry& e : entries_) {
    if (!std::isfinite(e.value)) continue;
    ++count_;
    sum_ += e.value;
    if (std::isfinite(e.var)) {
      sum_var_ += e.var;
    } else {
      ++no_std_;
    }
  }
}

double TrailingMean::Mean() const { return count_ == 0 ? kNaN : sum_ / count_; }

double TrailingMean::Std() const {
  if (count_ == 0 || no_std_ > 0) return kNaN;
  return std::sqrt(sum_var_ / count_);
}

double TrailingMean::Oldest() const { return entries_.empty() ? kNaN : entries_.front().t; }

std::uint64_t TrailingMean::OldestTag() const { return entries_.empty() ? 0 : entries_.front().tag; }

}  // namespace clothwind::sensors
