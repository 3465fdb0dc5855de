// What the monitoring display shows of the wind: a short history of speeds (the estimator's and
// the anemometer's), its windowed mean, the one-line summary text and a time-series image.
// ROS-free so the drawing is tested without rviz; nodes/wind_display_node.cc only moves messages.
#ifndef CLOTHWIND_SENSORS_WIND_PLOT_H_
#define CLOTHWIND_SENSORS_WIND_PLOT_H_

#include <deque>
#include <limits>
#include <string>

#include <opencv2/core.hpp>

namespace clothwind::sensors {

// One speed at one time.
struct WindSample {
  double t = 0.0;      // [s] any monotonic clock shared by all series (ROS time in seconds)
  double speed = 0.0;  // [m/s]
  double std = 0.0;    // [m/s] one standard deviation; NaN or 0 when none
};

// A time-ordered speed history that forgets samples older than its span.
class WindHistory {
 public:
  // Inputs:
  //   span  [s] how much history to keep (> 0)
  explicit WindHistory(double span) : span_(span) {}

  // Adds a sample (non-finite speeds and times are ignored: they mean "no reading"). A sample up to
  // kRestartAfter older than the newest is put in its place (two sources on one topic, jitter);
  // one older than that (the clock jumped back, e.g. a bag replayed again) clears the history first.
  void Add(const WindSample& s);
  static constexpr double kRestartAfter = 5.0;  // [s]

  // Mean speed of the samples with t in (t_now - window, t_now]; NaN when there are none.
  // Inputs:
  //   t_now   [s] end of the window
  //   window  [s] length of the window
  // Outputs:
  //   count   number of samples averaged (may be null)
  double Mean(double t_now, double window, int* count = nullptr) const;

  // [s] The part of the window (t_now - window, t_now] its samples span: t_now less the oldest
  // sample in it, at most `window`; 0 when none. What a mean "over the window" is over while the
  // history is younger than the window.
  double Span(double t_now, double window) const;

  const std::deque<WindSample>& samples() const { return samples_; }
  bool empty() const { return samples_.empty(); }
  const WindSample& back() const { return samples_.back(); }

 private:
  double span_;
  std::deque<WindSample> samples_;
};

// The summary line, e.g. "estimate 3.4 ± 0.3 m/s, 60 s mean 3.6 | anemometer 3.2 m/s (60 s mean)";
// a NaN estimate or anemometer mean is written as "--", a NaN/zero std and a NaN estimate mean
// are left out.
// Inputs:
//   estimate, estimate_std  [m/s] latest estimate and its standard deviation
//   anemometer_mean         [m/s] anemometer mean over the window
//   window                  [s] the means' window
//   estimate_mean           [m/s] the estimates' mean over the same window (what compares with
//                           the anemometer's mean: one clip shows its own 1.2 s of gusts)
//   anemometer_span, estimate_mean_span
//                           [s] what each mean spans (WindHistory::Span); NaN: the whole window.
//                           Shorter than the window by over a second, the mean is said as
//                           "14 of 60 s mean": early in a session a 14 s mean read as a minute's.
std::string WindSummaryText(double estimate, double estimate_std, double anemometer_mean, double window,
                            double estimate_mean = std::numeric_limits<double>::quiet_NaN(),
                            double anemometer_span = std::numeric_limits<double>::quiet_NaN(),
                            double estimate_mean_span = std::numeric_limits<double>::quiet_NaN());

// The monitor's top-down view shows about ±5 m around the anemometer: its wind arrow is drawn at
// kWindArrowMetresPerMps, at most kWindArrowMaxLength long (1 m per m/s ran off the view past
// 5 m/s, its head lost). Returns the factor [m per m/s] that scales velocity (vx, vy, vz) [m/s]
// to the arrow; 0 for a zero or non-finite velocity.
inline constexpr double kWindArrowMetresPerMps = 0.3, kWindArrowMaxLength = 4.5;
double WindArrowScale(double vx, double vy, double vz);

// Colours (BGR) of the plot's series; the legend and docs/monitor.md name them.
const cv::Scalar kEstimateColour(0, 140, 255);   // orange line, with a pale ±std band
const cv::Scalar kAnemometerColour(200, 110, 0); // blue line
const cv::Scalar kPlotBackground(255, 255, 255);
const cv::Scalar kPlotGrid(225, 225, 225);
// The plot area's margins [px]: room for the y labels on the left, the legend on top, the x labels
// below (public so a test finds the plot frame in an image rather than copying the numbers).
constexpr int kPlotLeft = 44, kPlotRight = 10, kPlotTop = 22, kPlotBottom = 24;

// Draws estimate vs anemometer speed over the last `window` seconds: time on x (now at the right
// edge), speed on y from 0 to a rounded-up maximum (at least 2 m/s), grid, axis labels, legend.
// Each series is a line broken at its gaps (WindSeriesGap), with a dot at every sample.
// Inputs:
//   estimate    estimator's history (std drawn as a band when finite and > 0)
//   anemometer  anemometer's history
//   t_now       [s] time at the right edge
//   window      [s] time span shown (> 0)
//   width, height  image size [px] (at least 160 by 120)
//   t_origin    [s] NaN (default): time labelled as seconds before now (the live monitor);
//               finite: time labelled as seconds since t_origin (a report over a session)
//   reference_name  the legend's name of the second series ("anemometer"; a report of clip
//               labels calls it what it is, the anemometer's mean over each clip's window)
// Returns a CV_8UC3 (bgr8) image height by width.
// Throws std::invalid_argument for a size too small or a window <= 0.
cv::Mat DrawWindPlot(const WindHistory& estimate, const WindHistory& anemometer, double t_now, double window,
                     int width, int height, double t_origin = std::numeric_limits<double>::quiet_NaN(),
                     const std::string& reference_name = "anemometer");

// The longest step between two samples of `h` in (t_now - window, t_now] that DrawWindPlot
// joins with a line: kWindSeriesGapFactor times the median step there, steps below a tenth of
// the mean step left out (two readings of one instant, as relative and true wind; a series' own rhythm:
// 1 s for a sonic anemometer, 48 s for a Fine Offset station, a clip's span for estimates);
// infinity with fewer than three samples there (no rhythm to judge by). A longer step is an
// outage (the sensor unplugged, sdn_node down) and the line breaks across it.
double WindSeriesGap(const WindHistory& h, double t_now, double window);
inline constexpr double kWindSeriesGapFactor = 3.0;

// The pixel row of a speed in a plot DrawWindPlot drew (for tests and overlays).
// Inputs: speed [m/s], y_max [m/s] top of the axis, height [px] image height
int WindPlotRow(double speed, double y_max, int height);

// The axis top DrawWindPlot uses for histories whose largest speed (+std) is max_speed [m/s]:
// 2 m/s at least, kWindPlotAxisCap at most (a speed above it is drawn at the top edge; one absurd
// value must not turn the axis into millions of grid lines).
double WindPlotAxisMax(double max_speed);
inline constexpr double kWindPlotAxisCap = 100.0;  // [m/s]

}  // namespace clothwind::sensors

#endif  // CLOTHWIND_SENSORS_WIND_PLOT_H_
