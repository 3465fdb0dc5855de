// What a replayed session's wind estimates add up to: a table of each clip's estimate beside its
// anemometer label, Table 1's metrics over the session (RMSE, Acc@0.5) plus the bias, and a plot
// of both over time. ROS-free: nodes/clip_report_node.cc only collects WindEstimate messages.
#ifndef CLOTHWIND_SENSORS_ESTIMATE_REPORT_H_
#define CLOTHWIND_SENSORS_ESTIMATE_REPORT_H_

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

namespace clothwind::sensors {

// One estimate, as a WindEstimate carries it.
struct EstimateRow {
  uint64_t sequence = 0;     // the clip's sequence number
  double end = 0;            // [s] stamp of the clip's last frame
  double speed = 0;          // [m/s] estimate
  double speed_std = 0;      // [m/s] its standard deviation; NaN if none
  double reference = 0;      // [m/s] the clip's anemometer label; NaN if none
  double latency = 0;        // [s] clip received -> estimate published
};

// Estimates against anemometer labels over the rows that have both (finite speed and reference).
struct EstimateSummary {
  int count = 0;          // rows
  int compared = 0;       // rows with a finite estimate and label
  double rmse = 0;        // [m/s] NaN when compared == 0
  double acc05 = 0;       // fraction with |estimate - label| <= 0.5 m/s; NaN when compared == 0
  double bias = 0;        // [m/s] mean of estimate - label; NaN when compared == 0
  double mean_label = 0;  // [m/s] mean of the labels compared; NaN when compared == 0
  double mean_latency = 0, max_latency = 0;  // [s] over all rows; 0 when there are none
  // The same three metrics for the trailing mean of the estimates — at each labelled row, the
  // mean speed of the rows whose `end` lies in (end - window, end] — against the row's label.
  // The field protocol labels a clip with the anemometer's mean over the last minute, so one
  // clip's estimate carries the gusts of its own 1.2 s while the label has averaged them out;
  // the trailing mean compares like with like. Rows in the first `window` seconds average what
  // there is. NaN when compared == 0.
  double window = 60;     // [s]
  double window_rmse = 0, window_acc05 = 0, window_bias = 0;
};

// Inputs: rows  in any order; window [s] of the trailing mean (> 0). Output: the summary above.
EstimateSummary SummariseEstimates(const std::vector<EstimateRow>& rows, double window = 60);

// A fixed-width table, one line per row sorted by `end`: sequence, time since t0, estimate ± std,
// label, error; then one "estimates:" line with the summary.
// Inputs: rows; t0 [s] the time printed as 0 (e.g. the first clip's start); window [s] of the
// trailing mean, the clips' label window (> 0; compare like with like).
std::string EstimateTable(const std::vector<EstimateRow>& rows, double t0, double window = 60);

// The rows and the summary as JSON ({"estimates": [...], "rmse", "acc05", "bias", "compared", ...};
// NaN written as null).
nlohmann::json EstimateJson(const std::vector<EstimateRow>& rows, double window = 60);

// Estimate (± std band) and anemometer label over the whole session, time since t0 on x: the
// monitor's DrawWindPlot over a window that spans every row, with the summary as a title line.
// Inputs: rows (at least one with a time: rows whose end is 0 or not finite are left out); t0 [s]
//         (0 or not finite: the first row's end); width, height [px] (at least 160 by 120);
//         window [s] the clips' label window (the reference series is the anemometer's mean over it).
// Returns a CV_8UC3 image. Throws std::invalid_argument for no rows with a time or a size too small.
cv::Mat DrawEstimatePlot(const std::vector<EstimateRow>& rows, double t0, int width, int height,
                         double window = 60);

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_ESTIMATE_REPORT_H_
