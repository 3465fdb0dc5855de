#include "sensors/wind_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/formatted.h"

namespace clothwind::sensors {
namespace {

constexpr int kLeft = kPlotLeft, kRight = kPlotRight, kTop = kPlotTop, kBottom = kPlotBottom;  // wind_plot.h

int PlotTop() { return kTop; }
int PlotBottom(int height) { return height - kBottom; }

int Column(double t, double t_now, double window, int width) {
  const double x0 = kLeft, x1 = width - kRight;
  return static_cast<int>(std::lround(x1 - (t_now - t) / window * (x1 - x0)));
}

// Draws one series as polylines (and its std band), clipped to the shown window, broken where
// the series has a gap (WindSeriesGap): a line across an outage would show readings never made.
void DrawSeries(cv::Mat& img, const WindHistory& h, double t_now, double window, double y_max,
                const cv::Scalar& colour, bool band) {
  const double gap = WindSeriesGap(h, t_now, window);
  std::vector<cv::Point> line;
  auto flush = [&] {
    if (line.size() == 1) cv::circle(img, line[0], 3, colour, cv::FILLED);
    if (line.size() > 1) cv::polylines(img, line, false, colour, 2, cv::LINE_AA);
    for (const cv::Point& p : line) cv::circle(img, p, 2, colour, cv::FILLED);
    line.clear();
  };
  double previous = std::numeric_limits<double>::quiet_NaN();
  for (const WindSample& s : h.samples()) {
    if (s.t < t_now - window || s.t > t_now) continue;
    if (s.t - previous > gap) flush();
    previous = s.t;
    const int x = Column(s.t, t_now, window, img.cols);
    if (band && std::isfinite(s.std) && s.std > 0) {
      // Pale version of the colour: the band stays behind the lines.
      const cv::Scalar pale = (colour + cv::Scalar(255, 255, 255) * 2) / 3;
      cv::line(img, {x, WindPlotRow(s.speed + s.std, y_max, img.rows)},
               {x, WindPlotRow(std::max(0.0, s.speed - s.std), y_max, img.rows)}, pale, 3);
    }
    line.emplace_back(x, WindPlotRow(s.speed, y_max, img.rows));
  }
  flush();
}

}  // namespace

double WindSeriesGap(const WindHistory& h, double t_now, double window) {
  std::vector<double> steps;
  double previous = std::numeric_limits<double>::quiet_NaN();
  for (const WindSample& s : h.samples()) {
    if (s.t < t_now - window || s.t > t_now) continue;
    if (std::isfinite(previous)) steps.push_back(s.t - previous);
    previous = s.t;
  }
  if (steps.size() < 2) return std::numeric_limits<double>::infinity();
  // Steps far below the mean step are pairs, not the rhythm: an instrument sending its relative
  // and its true wind (MWV R and T) milliseconds apart made the median flip between 2 ms and the
  // period with each new sample, and the line between dots and a line.
  double mean = 0;
  for (double s : steps) mean += s;
  mean /= steps.size();
  steps.erase(std::remove_if(steps.begin(), steps.end(), [&](double s) { return s < 0.1 * mean; }), steps.end());
  if (steps.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double median = steps[steps.size() / 2];
  return median > 0 ? kWindSeriesGapFactor * median : std::numeric_limits<double>::infinity();
}

void WindHistory::Add(const WindSample& s) {
  if (!std::isfinite(s.speed) || !std::isfinite(s.t)) return;
  if (!samples_.empty() && s.t < samples_.back().t - kRestartAfter) samples_.clear();
  if (samples_.empty() || s.t >= samples_.back().t) {
    samples_.push_back(s);
  } else {  // a little out of order: keep the history sorted by time
    const auto at = std::upper_bound(samples_.begin(), samples_.end(), s.t,
                                     [](double t, const WindSample& x) { return t < x.t; });
    samples_.insert(at, s);
  }
  const double newest = samples_.back().t;
  while (!samples_.empty() && samples_.front().t < newest - span_) samples_.pop_front();
}

double WindHistory::Mean(double t_now, double window, int* count) const {
  double sum = 0.0;
  int n = 0;
  for (const WindSample& s : samples_) {
    if (s.t > t_now - window && s.t <= t_now) {
      sum += s.speed;
      ++n;
    }
  }
  if (count) *count = n;
  return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

double WindHistory::Span(double t_now, double window) const {
  double oldest = std::numeric_limits<double>::infinity();
  for (const WindSample& s : samples_)
    if (s.t > t_now - window && s.t <= t_now) oldest = std::min(oldest, s.t);
  return std::isfinite(oldest) ? std::min(window, t_now - oldest) : 0.0;
}

namespace {

// "60 s mean", or "14 of 60 s mean" while the mean spans less than the window.
std::string MeanLabel(double window, double span) {
  if (!std::isfinite(span) || span >= window - 1.0) return Formatted("%.0f s mean", window);
  return Formatted("%.0f of %.0f s mean", std::max(span, 0.0), window);
}

}  // namespace

std::string WindSummaryText(double estimate, double estimate_std, double anemometer_mean, double window,
                            double estimate_mean, double anemometer_span, double estimate_mean_span) {
  std::string text = "estimate ";
  if (std::isfinite(estimate)) {
    text += Formatted("%.1f", estimate);
    if (std::isfinite(estimate_std) && estimate_std > 0) text += Formatted(" \xC2\xB1 %.1f", estimate_std);
    text += " m/s";
    if (std::isfinite(estimate_mean))
      text += ", " + MeanLabel(window, estimate_mean_span) + Formatted(" %.1f", estimate_mean);
  } else {
    text += "--";
  }
  text += " | anemometer ";
  text += std::isfinite(anemometer_mean) ? Formatted("%.1f m/s", anemometer_mean) : std::string("--");
  text += " (" + MeanLabel(window, std::isfinite(anemometer_mean) ? anemometer_span : std::nan("")) + ")";
  return text;
}

double WindArrowScale(double vx, double vy, double vz) {
  const double speed = std::sqrt(vx * vx + vy * vy + vz * vz);
  if (!(std::isfinite(speed) && speed > 0)) return 0.0;
  return std::min(kWindArrowMetresPerMps, kWindArrowMaxLength / speed);
}

double WindPlotAxisMax(double max_speed) {
  if (std::isnan(max_speed) || max_speed < 2.0) return 2.0;
  return std::min(kWindPlotAxisCap, std::ceil(max_speed * 1.1));  // headroom: the top line off the frame
}

int WindPlotRow(double speed, double y_max, int height) {
  const double y0 = PlotBottom(height), y1 = PlotTop();
  const double clamped = std::clamp(speed, 0.0, y_max);
  return static_cast<int>(std::lround(y0 - clamped / y_max * (y0 - y1)));
}

cv::Mat DrawWindPlot(const WindHistory& estimate, const WindHistory& anemometer, double t_now, double window,
                     int width, int height, double t_origin, const std::string& reference_name) {
  if (width < 160 || height < 120) {
    throw std::invalid_argument("DrawWindPlot: image " + std::to_string(width) + "x" + std::to_string(height) +
                                " too small (expected at least 160x120)");
  }
  if (!(window > 0) || !std::isfinite(window))
    throw std::invalid_argument("DrawWindPlot: window must be a finite time > 0 s");
  if (!std::isfinite(t_now)) throw std::invalid_argument("DrawWindPlot: t_now must be finite");
  double top = 0.0;
  for (const WindHistory* h : {&estimate, &anemometer}) {
    for (const WindSample& s : h->samples()) {
      if (s.t < t_now - window || s.t > t_now) continue;
      top = std::max(top, s.speed + (std::isfinite(s.std) ? std::max(0.0, s.std) : 0.0));
    }
  }
  const double y_max = WindPlotAxisMax(top);

  cv::Mat img(height, width, CV_8UC3, kPlotBackground);
  const cv::Scalar grid = kPlotGrid, ink(60, 60, 60);
  const double font = 0.4;
  // Horizontal grid at a round step, labelled in m/s.
  const double step = y_max <= 4 ? 0.5 : y_max <= 10 ? 1.0 : y_max <= 20 ? 2.0 : y_max <= 50 ? 5.0 : 10.0;
  for (double v = 0.0; v <= y_max + 1e-9; v += step) {
    const int y = WindPlotRow(v, y_max, height);
    cv::line(img, {kLeft, y}, {width - kRight, y}, grid, 1);
    cv::putText(img, Formatted(step < 1 ? "%.1f" : "%.0f", v), {4, y + 4}, cv::FONT_HERSHEY_SIMPLEX, font, ink, 1,
                cv::LINE_AA);
  }
  // Vertical grid every 10 s (every 30 s or 60 s for long windows), labelled in seconds before now
  // (live monitor) or in seconds since t_origin (a report over a whole session).
  // At most ~12 lines whatever the window (a report over a session with one stamp at 0 spans decades).
  double tstep = window <= 60 ? 10 : window <= 240 ? 30 : 60;
  while (window / tstep > 12) tstep *= window / tstep > 120 ? 10 : 2;
  const bool since_origin = std::isfinite(t_origin);
  for (double a = 0.0; a <= window + 1e-9; a += tstep) {
    const double t = since_origin ? t_now - window + a : t_now - a;
    const int x = Column(t, t_now, window, width);
    cv::line(img, {x, PlotTop()}, {x, PlotBottom(height)}, grid, 1);
    const bool right_edge = x > width - kRight - 30;  // its label kept inside the image
    const std::string label = since_origin ? Formatted("%.0f s", t - t_origin) : a == 0.0 ? std::string("now")
                                                                                      : Formatted("-%.0f s", a);
    cv::putText(img, label, {right_edge ? x - 30 : x - 14, height - 8}, cv::FONT_HERSHEY_SIMPLEX, font, ink, 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, {kLeft, PlotTop()}, {width - kRight, PlotBottom(height)}, ink, 1);

  DrawSeries(img, estimate, t_now, window, y_max, kEstimateColour, true);
  DrawSeries(img, anemometer, t_now, window, y_max, kAnemometerColour, false);

  // Legend on the top margin.
  cv::putText(img, "m/s", {4, 14}, cv::FONT_HERSHEY_SIMPLEX, font, ink, 1, cv::LINE_AA);
  cv::line(img, {kLeft, 10}, {kLeft + 18, 10}, kEstimateColour, 2);
  cv::putText(img, "estimate", {kLeft + 22, 14}, cv::FONT_HERSHEY_SIMPLEX, font, ink, 1, cv::LINE_AA);
  cv::line(img, {kLeft + 100, 10}, {kLeft + 118, 10}, kAnemometerColour, 2);
  cv::putText(img, reference_name, {kLeft + 122, 14}, cv::FONT_HERSHEY_SIMPLEX, font, ink, 1, cv::LINE_AA);
  return img;
}

}  // namespace clothwind::sensors
