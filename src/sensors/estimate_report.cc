#include "sensors/estimate_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "common/formatted.h"
#include "sensors/trailing_mean.h"
#include "sensors/wind_plot.h"

namespace clothwind::sensors {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

nlohmann::json Number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

std::vector<EstimateRow> SortedByEnd(std::vector<EstimateRow> rows) {
  std::stable_sort(rows.begin(), rows.end(), [](const EstimateRow& a, const EstimateRow& b) { return a.end < b.end; });
  return rows;
}

std::string SummaryLine(const EstimateSummary& s) {
  return Formatted("estimates: %d, %d with an anemometer label: RMSE %.3f m/s, Acc@0.5 %.3f, bias %+.3f m/s "
                "(mean label %.3f m/s); latency mean %.1f ms, max %.1f ms\n"
                "trailing %.0f s mean of the estimates against the label: RMSE %.3f m/s, Acc@0.5 %.3f, bias %+.3f m/s",
                s.count, s.compared, s.rmse, s.acc05, s.bias, s.mean_label, s.mean_latency * 1e3, s.max_latency * 1e3,
                s.window, s.window_rmse, s.window_acc05, s.window_bias);
}

}  // namespace

EstimateSummary SummariseEstimates(const std::vector<EstimateRow>& rows, double window) {
  EstimateSummary s;
  s.window = window;
  s.count = static_cast<int>(rows.size());
  double se = 0, err = 0, label = 0, latency = 0;
  int within = 0;
  for (const EstimateRow& r : rows) {
    latency += r.latency;
    s.max_latency = std::max(s.max_latency, r.latency);
    if (!std::isfinite(r.speed) || !std::isfinite(r.reference)) continue;
    const double e = r.speed - r.reference;
    se += e * e;
    err += e;
    label += r.reference;
    within += std::fabs(e) <= 0.5;
    ++s.compared;
  }
  s.mean_latency = rows.empty() ? 0.0 : latency / rows.size();
  if (s.compared == 0) {
    s.rmse = s.acc05 = s.bias = s.mean_label = kNaN;
  } else {
    s.rmse = std::sqrt(se / s.compared);
    s.acc05 = static_cast<double>(within) / s.compared;
    s.bias = err / s.compared;
    s.mean_label = label / s.compared;
  }
  // Trailing means, over the rows in time order.
  TrailingMean trailing(window);
  double wse = 0, werr = 0;
  int wwithin = 0, wcompared = 0;
  for (const EstimateRow& r : SortedByEnd(rows)) {
    trailing.Add(r.end, r.speed);
    // The rows `compared` counts: a finite estimate (so the mean is finite) and label.
    if (!std::isfinite(r.speed) || !std::isfinite(r.reference)) continue;
    ++wcompared;
    const double e = trailing.Mean() - r.reference;
    wse += e * e;
    werr += e;
    wwithin += std::fabs(e) <= 0.5;
  }
  if (wcompared == 0) {
    s.window_rmse = s.window_acc05 = s.window_bias = kNaN;
  } else {
    s.window_rmse = std::sqrt(wse / wcompared);
    s.window_acc05 = static_cast<double>(wwithin) / wcompared;
    s.window_bias = werr / wcompared;
  }
  return s;
}

std::string EstimateTable(const std::vector<EstimateRow>& rows, double t0, double window) {
  std::string out;
  char line[200];
  std::snprintf(line, sizeof line, "%5s  %10s  %14s  %10s  %9s  %8s\n", "seq", "end [s]", "estimate m/s", "label m/s",
                "error", "latency");
  out += line;
  for (const EstimateRow& r : SortedByEnd(rows)) {
    // 14 characters on screen either way, under the heading's 14 ("±" is two bytes, so the
    // column is written as it is rather than padded by printf, which counts bytes).
    // Formatted to their full length: a speed of 1e300 (301 digits) overflowed fixed buffers, and
    // the row lost its end of line and the summary after it was cut short.
    const std::string estimate =
        std::isfinite(r.speed_std) ? Formatted("%6.2f \xC2\xB1%6.2f", r.speed, r.speed_std)
                                   : Formatted("%6.2f        ", r.speed);
    out += Formatted("%5llu  %10.2f  %s  %10.2f  %+9.2f  %6.1fms\n", static_cast<unsigned long long>(r.sequence),
                     r.end - t0, estimate.c_str(), r.reference, r.speed - r.reference, r.latency * 1e3);
  }
  return out + SummaryLine(SummariseEstimates(rows, window)) + "\n";
}

nlohmann::json EstimateJson(const std::vector<EstimateRow>& rows, double window) {
  nlohmann::json list = nlohmann::json::array();
  for (const EstimateRow& r : SortedByEnd(rows)) {
    list.push_back({{"sequence", r.sequence}, {"end", r.end}, {"speed", Number(r.speed)},
                    {"speed_std", Number(r.speed_std)}, {"reference", Number(r.reference)}, {"latency", r.latency}});
  }
  const EstimateSummary s = SummariseEstimates(rows, window);
  return {{"estimates", list},       {"count", s.count},         {"compared", s.compared},
          {"rmse", Number(s.rmse)},  {"acc05", Number(s.acc05)}, {"bias", Number(s.bias)},
          {"mean_label", Number(s.mean_label)}, {"mean_latency", s.mean_latency}, {"max_latency", s.max_latency},
          {"window", s.window},      {"window_rmse", Number(s.window_rmse)},
          {"window_acc05", Number(s.window_acc05)}, {"window_bias", Number(s.window_bias)}};
}

cv::Mat DrawEstimatePlot(const std::vector<EstimateRow>& rows, double t0, int width, int height,
                         double window) {
  if (rows.empty()) throw std::invalid_argument("DrawEstimatePlot: no estimates to plot");
  // An estimate without a time (a clip stamped 0) would stretch the axis over decades: left out.
  std::vector<EstimateRow> sorted;
  for (const EstimateRow& r : SortedByEnd(rows))
    if (std::isfinite(r.end) && r.end > 0) sorted.push_back(r);
  if (sorted.empty()) throw std::invalid_argument("DrawEstimatePlot: no estimate has a time (clip end) to plot");
  if (!std::isfinite(t0) || t0 <= 0) t0 = sorted.front().end;
  const double t_end = sorted.back().end;
  const double span = std::max(1.0, t_end - std::min(t0, sorted.front().end));
  WindHistory estimate(span * 2 + 1), label(span * 2 + 1);
  for (const EstimateRow& r : sorted) {
    estimate.Add({r.end, r.speed, r.speed_std});
    label.Add({r.end, r.reference, 0.0});
  }
  char reference[64];
  std::snprintf(reference, sizeof reference, "label (anemometer %.0f s mean)", window);
  cv::Mat img = DrawWindPlot(estimate, label, t_end, span, width, height, t0, reference);
  // The session's figures under the legend, where DrawWindPlot leaves the top margin free.
  const EstimateSummary s = SummariseEstimates(rows, window);
  char text[160];
  std::snprintf(text, sizeof text, "RMSE %.2f m/s  Acc@0.5 %.2f  (%d clips)", s.rmse, s.acc05, s.compared);
  cv::putText(img, text, {std::max(4, width - 300), 14}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(60, 60, 60), 1,
              cv::LINE_AA);
  return img;
}

}  // namespace clothwind::sensors
