#include "sensors/trailing_mean.h"

#include <algorithm>
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

void TrailingMean::Add(double t, double value, double std) {
  if (!entries_.empty() && t < entries_.back().t) *this = TrailingMean(window_);
  const bool finite = std::isfinite(value);
  const double var = std::isfinite(std) ? std * std : kNaN;
  entries_.push_back({t, finite ? value : kNaN, var});
  if (finite) {
    ++count_;
    sum_ += value;
    if (std::isfinite(var)) {
      sum_var_ += var;
    } else {
      ++no_std_;
    }
  }
  while (!entries_.empty() && entries_.front().t <= t - window_) {
    const Entry& e = entries_.front();
    if (std::isfinite(e.value)) {
      --count_;
      sum_ -= e.value;
      if (std::isfinite(e.var)) {
        sum_var_ -= e.var;
      } else {
        --no_std_;
      }
    }
    entries_.pop_front();
  }
  // Running sums drift with many additions and removals; an empty window resets them exactly.
  if (count_ == 0) sum_ = sum_var_ = 0;
}

double TrailingMean::Mean() const { return count_ == 0 ? kNaN : sum_ / count_; }

double TrailingMean::Std() const {
  if (count_ == 0 || no_std_ > 0) return kNaN;
  return std::sqrt(std::max(0.0, sum_var_) / count_);
}

double TrailingMean::Oldest() const { return entries_.empty() ? kNaN : entries_.front().t; }

}  // namespace clothwind::sensors
