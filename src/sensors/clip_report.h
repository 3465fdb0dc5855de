// What a replay's clips add up to: a table of each clip (sequence, start, end, frames, frame
// spacing, wind label) with totals, and the same as JSON. ROS-free: nodes/clip_report_node.cc only
// collects Clip messages; the estimates' side is sensors/estimate_report.h.
#ifndef CLOTHWIND_SENSORS_CLIP_REPORT_H_
#define CLOTHWIND_SENSORS_CLIP_REPORT_H_

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sensors/estimate_report.h"

namespace clothwind::sensors {

// One clip, as a Clip message carries it.
struct ClipRow {
  uint64_t sequence = 0;
  double start = 0, end = 0;      // [s] first and last frame stamps; NaN without frame stamps
  uint32_t frames = 0;
  double max_spacing_error = 0;   // [s] largest |frame interval - 1/frame rate|
  double mean = 0, std = 0;       // [m/s] the anemometer label and its spread; NaN without readings
  double direction = 0;           // [rad] the label's mean direction
  uint32_t count = 0;             // anemometer readings in the label
  uint32_t width = 0, height = 0; // [px]
};

// The largest |interval - 1/frame_rate| [s] between successive stamps [s] (0 for fewer than two).
// In double seconds: one corrupt stamp (TIME_MAX) gives a huge error, not a throw.
double MaxSpacingError(const std::vector<double>& stamps, double frame_rate);

// The time a report prints as 0 [s]: the earliest positive clip start, else the first estimate's
// positive clip end, else 0.
double ReportOrigin(const std::vector<ClipRow>& clips, const std::vector<EstimateRow>& estimates);

// How many clips have no estimate of their sequence number.
size_t Unestimated(const std::vector<ClipRow>& clips, const std::vector<EstimateRow>& estimates);

// What the clips were recorded with, and the report's wall time.
struct ClipReportContext {
  double frame_rate = 0;    // [Hz] the clips' (the last clip's)
  double label_window = 0;  // [s] the clips' anemometer label window
  double wall = 0;          // [s] wall time the report covers
};

// A fixed-width table, one line per clip in arrival order, times since t0, then one "totals:" line
// (clips, frames, size, labelled clips and the mean of their labels, first to last frame, worst
// frame spacing error, wall time).
std::string ClipTable(const std::vector<ClipRow>& clips, double t0, const ClipReportContext& context);

// The clips and totals as JSON ({"clips": [...], "total_clips", "total_frames", "labelled_clips",
// "frame_rate", "label_window", "wall_seconds"}; a NaN label written as null).
nlohmann::json ClipJson(const std::vector<ClipRow>& clips, const ClipReportContext& context);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_CLIP_REPORT_H_
