#include "sensors/clip_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/formatted.h"

namespace clothwind::sensors {

double MaxSpacingError(const std::vector<double>& stamps, double frame_rate) {
  double worst = 0;
  for (size_t i = 1; i < stamps.size(); ++i)
    worst = std::max(worst, std::fabs(stamps[i] - stamps[i - 1] - 1.0 / frame_rate));
  return worst;
}

double ReportOrigin(const std::vector<ClipRow>& clips, const std::vector<EstimateRow>& estimates) {
  double t0 = std::numeric_limits<double>::infinity();
  for (const ClipRow& r : clips)
    if (std::isfinite(r.start) && r.start > 0) t0 = std::min(t0, r.start);
  if (std::isfinite(t0)) return t0;
  for (const EstimateRow& e : estimates)
    if (std::isfinite(e.end) && e.end > 0) return e.end;
  return 0.0;
}

size_t Unestimated(const std::vector<ClipRow>& clips, const std::vector<EstimateRow>& estimates) {
  std::vector<uint64_t> seen;
  for (const EstimateRow& e : estimates) seen.push_back(e.sequence);
  std::sort(seen.begin(), seen.end());
  size_t missing = 0;
  for (const ClipRow& r : clips) missing += !std::binary_search(seen.begin(), seen.end(), r.sequence);
  return missing;
}

std::string ClipTable(const std::vector<ClipRow>& clips, double t0, const ClipReportContext& context) {
  std::string text = Formatted("%5s  %-12s  %-12s  %6s  %7s  %9s  %8s  %8s  %5s  %8s\n", "seq", "start [s]", "end [s]",
                          "frames", "span", "dt err", "wind m/s", "std", "count", "dir rad");
  double label_sum = 0, worst_spacing = 0;
  size_t labelled = 0, frames = 0;
  for (const ClipRow& r : clips) {
    text += Formatted("%5llu  %12.3f  %12.3f  %6u  %6.3fs  %7.1fus  %8.3f  %8.3f  %5u  %8.3f\n",
                 static_cast<unsigned long long>(r.sequence), r.start - t0, r.end - t0, r.frames, r.end - r.start,
                 r.max_spacing_error * 1e6, r.mean, r.std, r.count, r.direction);
    frames += r.frames;
    worst_spacing = std::max(worst_spacing, r.max_spacing_error);
    if (r.count > 0) {
      label_sum += r.mean;
      ++labelled;
    }
  }
  const double covered = clips.empty() ? 0.0 : clips.back().end - clips.front().start;
  text += Formatted("totals: %zu clips, %zu frames at %.1f fps (%dx%d), %zu labelled (label window %.0f s, mean of "
               "labels %.3f m/s), first to last frame %.2f s, worst frame spacing error %.1f us, wall %.1f s\n",
               clips.size(), frames, context.frame_rate, clips.empty() ? 0 : static_cast<int>(clips.front().width),
               clips.empty() ? 0 : static_cast<int>(clips.front().height), labelled, context.label_window,
               labelled ? label_sum / labelled : std::nan(""), covered, worst_spacing * 1e6, context.wall);
  return text;
}

nlohmann::json ClipJson(const std::vector<ClipRow>& clips, const ClipReportContext& context) {
  auto number_or_null = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json rows = nlohmann::json::array();
  size_t labelled = 0, frames = 0;
  for (const ClipRow& r : clips) {
    frames += r.frames;
    labelled += r.count > 0;
    rows.push_back({{"sequence", r.sequence}, {"start", r.start}, {"end", r.end}, {"frames", r.frames},
                    {"width", r.width}, {"height", r.height}, {"max_spacing_error", r.max_spacing_error},
                    {"wind_mean", number_or_null(r.mean)}, {"wind_std", number_or_null(r.std)},
                    {"wind_count", r.count}});
  }
  return {{"clips", rows},
          {"total_clips", clips.size()},
          {"total_frames", frames},
          {"labelled_clips", labelled},
          {"frame_rate", context.frame_rate},
          {"label_window", context.label_window},
          {"wall_seconds", context.wall}};
}

}  // namespace clothwind::sensors
