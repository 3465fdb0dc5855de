// clip_report_node: listens to `clips` during a replay and, when the replay is over, prints what
// came out (a table: sequence, start, end, frames, spacing, wind label) with totals, writes the same
// as JSON (~summary) and exits, which ends the launch when the node is marked required.
// With ~estimates it also listens to `wind/estimate` (sdn_node) and adds a table of each clip's
// estimate beside its anemometer label, the session's RMSE and Acc@0.5, and a plot (~estimate_plot).
//
// "Over": the clock (sim time from rosbag play --clock) has not moved for ~idle_timeout wall
// seconds after it started, and no clip has arrived in that time either (the clip buffer labels
// its last waiting clips ~flush_after wall seconds after its input stops: ~idle_timeout is raised
// to the clip buffer's clip_buffer/flush_after + 2 s when it is shorter). With ~estimates, while
// clips still lack their estimate it waits longer, by twice the model's slowest pace so far, at
// most ~estimate_wait (60 s) more (a model slower than ~idle_timeout a clip had its backlog cut
// off; sensors/replay_end.h), and says when the report ends with clips unestimated. ~max_wall bounds it;
// ~start_timeout gives up when the clock never starts. Interrupted (Ctrl-C), it still prints and
// writes what it has; a file it cannot write is an error that does not cost the others.
#include <cmath>
#include <csignal>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>

#include <clothwind/Clip.h>
#include <clothwind/WindEstimate.h>
#include <opencv2/imgcodecs.hpp>

#include "ros_bridge/ros_log.h"
#include "ros_bridge/strict_param.h"
#include "sensors/clip_report.h"
#include "sensors/dataset_writer.h"
#include "sensors/estimate_report.h"
#include "sensors/replay_end.h"

namespace {

class ClipReport {
 public:
  explicit ClipReport(clothwind::ros_bridge::StrictParams& params) {
    idle_timeout_ = params.Get("idle_timeout", 5.0);
    estimate_wait_ = params.Get("estimate_wait", 60.0);
    max_wall_ = params.Get("max_wall", 0.0);
    start_timeout_ = params.Get("start_timeout", 60.0);
    summary_path_ = clothwind::ros_bridge::OutputFileParam("~summary", params.Get("summary", ""));
    want_estimates_ = params.Get("estimates", false);
    estimate_plot_path_ = clothwind::ros_bridge::OutputFileParam("~estimate_plot", params.Get("estimate_plot", ""));
    // The plot is of the estimates: without them it was silently not drawn.
    if (!estimate_plot_path_.empty() && !want_estimates_)
      throw std::invalid_argument("~estimate_plot " + estimate_plot_path_ +
                                  " plots the estimates: it needs ~estimates true (replay.launch: model:=)");
    auto finite = [](double v) { return std::isfinite(v); };
    if (!(finite(idle_timeout_) && idle_timeout_ > 0))
      throw std::invalid_argument("~idle_timeout must be a finite time > 0 s, got " + std::to_string(idle_timeout_));
    if (!(finite(estimate_wait_) && estimate_wait_ >= 0))
      throw std::invalid_argument("~estimate_wait must be a finite time >= 0 s, got " + std::to_string(estimate_wait_));
    // The clip buffer flushes its last clips ~flush_after wall seconds after its input stops; a
    // report over before that left them out, silently.
    double flush_after = 0;
    if (ros::param::get("clip_buffer/flush_after", flush_after) && std::isfinite(flush_after) &&
        idle_timeout_ < flush_after + 2.0) {
      std::printf("clip_report: ~idle_timeout %.1f s raised to %.1f s: clip_buffer/flush_after is %.1f s\n",
                  idle_timeout_, flush_after + 2.0, flush_after);
      idle_timeout_ = flush_after + 2.0;
    }
    if (!(finite(start_timeout_) && start_timeout_ > 0))
      throw std::invalid_argument("~start_timeout must be a finite time > 0 s, got " + std::to_string(start_timeout_));
    if (!(finite(max_wall_) && max_wall_ >= 0))
      throw std::invalid_argument("~max_wall must be a finite time >= 0 s (0: no bound), got " +
                                  std::to_string(max_wall_));
    ros::NodeHandle nh;
    sub_ = nh.subscribe("clips", 50, &ClipReport::OnClip, this);
    if (want_estimates_) estimate_sub_ = nh.subscribe("wind/estimate", 50, &ClipReport::OnEstimate, this);
    // The player's clock messages, paused or not: a paused bag is not an ended one.
    clock_sub_ = nh.subscribe("/clock", 10, &ClipReport::OnClockMessage, this);
    start_wall_ = ros::SteadyTime::now();
    clothwind::sensors::ReplayEndOptions end_options;
    end_options.idle_timeout = idle_timeout_;
    end_options.estimate_wait = estimate_wait_;
    end_options.max_wall = max_wall_;
    end_options.start_timeout = start_timeout_;
    end_.emplace(end_options, start_wall_.toSec());
    timer_ = nh.createSteadyTimer(ros::WallDuration(0.5), &ClipReport::OnTimer, this);
  }

 private:
  void OnClockMessage(const rosgraph_msgs::Clock::ConstPtr&) {
    const double wall = ros::SteadyTime::now().toSec();
    end_->Clock(ros::Time::now().toSec(), wall);  // the clock's start, if this is it
    end_->Player(wall);
  }

  void OnClip(const clothwind::Clip::ConstPtr& c) {
    end_->Activity(ros::SteadyTime::now().toSec());
    clothwind::sensors::ClipRow r;
    r.sequence = c->sequence;
    r.frames = c->num_frames;
    r.start = c->frame_stamps.empty() ? NAN : c->frame_stamps.front().toSec();
    r.end = c->frame_stamps.empty() ? NAN : c->frame_stamps.back().toSec();
    // In double seconds: ros::Time arithmetic throws beyond 32 bits, and one corrupt stamp
    // (TIME_MAX) ended the node before it printed or wrote anything of the good clips.
    std::vector<double> stamps;
    for (const ros::Time& t : c->frame_stamps) stamps.push_back(t.toSec());
    r.max_spacing_error = clothwind::sensors::MaxSpacingError(stamps, c->frame_rate);
    r.mean = c->wind_mean;
    r.std = c->wind_std;
    r.count = c->wind_count;
    r.direction = c->wind_direction_mean;
    r.width = c->width;
    r.height = c->height;
    rate_ = c->frame_rate;
    if (std::isfinite(c->label_window) && c->label_window > 0) window_ = c->label_window;
    rows_.push_back(r);
  }

  void OnEstimate(const clothwind::WindEstimate::ConstPtr& e) {
    end_->Estimate(ros::SteadyTime::now().toSec());
    estimates_.push_back({e->clip_sequence, e->clip_end.toSec(), e->speed, e->speed_std, e->reference_speed,
                          e->latency});
  }

  // The trailing mean's window: the clips' label window, 60 s before any clip came.
  double TrailingWindow() const { return window_ > 0 ? window_ : 60.0; }

  // The estimates' table, summary and plot (with ~estimates); adds them to the summary JSON.
  void PrintEstimates(double t0, nlohmann::json* summary) {
    namespace cs = clothwind::sensors;
    std::printf("\nestimate_report: %zu estimate(s) from the replay (label: the clip's anemometer mean)\n",
                estimates_.size());
    // The trailing mean over the clips' own label window: like with like.
    std::printf("%s", cs::EstimateTable(estimates_, t0, TrailingWindow()).c_str());
    (*summary)["estimates"] = cs::EstimateJson(estimates_, TrailingWindow());
  }

  // The plot after the summary: a plot that cannot be drawn or written costs only itself.
  bool WritePlot(double t0) {
    namespace cs = clothwind::sensors;
    if (estimate_plot_path_.empty() || estimates_.empty()) return true;
    try {
      std::vector<uchar> png;
      if (!cv::imencode(".png", cs::DrawEstimatePlot(estimates_, t0, 800, 360, TrailingWindow()), png) || png.empty())
        throw std::runtime_error("PNG encoding failed");
      cs::WriteFileAtomically(estimate_plot_path_, std::string(png.begin(), png.end()));
      std::printf("estimate plot: %s\n", estimate_plot_path_.c_str());
      return true;
    } catch (const std::exception& e) {
      // Also after spin() (Ctrl-C), when only stderr still prints (ros_bridge/ros_log.h).
      clothwind::ros_bridge::RosLog(clothwind::sensors::LogLevel::kError,
                                    std::string("clip_report: no estimate plot: ") + e.what());
      return false;
    }
  }

  void OnTimer(const ros::SteadyTimerEvent&) {
    const double wall_now = ros::SteadyTime::now().toSec();
    end_->Clock(ros::Time::now().toSec(), wall_now);
    const double wall = wall_now - start_wall_.toSec();
    switch (end_->Check(wall_now, Unestimated())) {
      case clothwind::sensors::ReplayVerdict::kRunning:
        return;
      case clothwind::sensors::ReplayVerdict::kNoClock:
        std::fprintf(stderr, "clip_report: the clock never started in %.0f s (is rosbag play waiting for a subscriber?)\n",
                     start_timeout_);
        break;
      case clothwind::sensors::ReplayVerdict::kMaxWall:
        std::printf("clip_report: stopped after ~max_wall = %.0f s, the replay still running: the report covers "
                    "only what came before\n", max_wall_);
        break;
      case clothwind::sensors::ReplayVerdict::kOver:
        break;
    }
    Print(wall);
    ros::shutdown();
  }

  // Clips that have come without their estimate (with ~estimates).
  size_t Unestimated() const { return want_estimates_ ? clothwind::sensors::Unestimated(rows_, estimates_) : 0; }

  // Prints and writes the report once (from the timer, or after spin() when interrupted).
  // Returns false when a file could not be written.
 public:
  bool Finish() {
    if (printed_) return ok_;
    return Print((ros::SteadyTime::now() - start_wall_).toSec());
  }

 private:
  bool Print(double wall) {
    printed_ = true;
    if (const size_t missing = Unestimated())
      std::printf("clip_report: %zu of %zu clips have no estimate (sdn_node still working, or it refused them or "
                  "found no motion in them): "
                  "the estimates' report covers the others\n", missing, rows_.size());
    std::printf("\nclip_report: %zu clip(s) from the replay\n", rows_.size());
    // Times from the earliest clip start there is (a clip without frame_stamps has none); else
    // the first estimate's clip end; 0 when there is neither.
    const double t0 = clothwind::sensors::ReportOrigin(rows_, estimates_);
    const clothwind::sensors::ClipReportContext context{rate_, window_, wall};
    std::printf("%s", clothwind::sensors::ClipTable(rows_, t0, context).c_str());
    nlohmann::json j = clothwind::sensors::ClipJson(rows_, context);
    if (want_estimates_) PrintEstimates(t0, &j);
    std::fflush(stdout);
    ok_ = true;
    if (!summary_path_.empty()) {
      try {
        clothwind::sensors::WriteFileAtomically(summary_path_, j.dump(1) + "\n");
      } catch (const std::exception& e) {
        clothwind::ros_bridge::RosLog(clothwind::sensors::LogLevel::kError,
                                      std::string("clip_report: no summary: ") + e.what());
        ok_ = false;
      }
    }
    if (want_estimates_) ok_ = WritePlot(t0) && ok_;
    std::fflush(stdout);
    return ok_;
  }

  double idle_timeout_ = 5.0, max_wall_ = 0.0, start_timeout_ = 60.0, estimate_wait_ = 60.0;
  std::string summary_path_, estimate_plot_path_;
  bool want_estimates_ = false;
  ros::Subscriber sub_, estimate_sub_, clock_sub_;
  std::vector<clothwind::sensors::EstimateRow> estimates_;
  ros::SteadyTimer timer_;
  ros::SteadyTime start_wall_;
  std::optional<clothwind::sensors::ReplayEnd> end_;  // when the replay is over (sensors/replay_end.h)
  bool printed_ = false, ok_ = true;
  std::vector<clothwind::sensors::ClipRow> rows_;
  double rate_ = 0.0, window_ = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "clip_report");
  // SIGTERM (systemd, docker stop, a plain kill) ends the spin like Ctrl-C, so the report is still
  // printed and its files written rather than lost with the process.
  std::signal(SIGTERM, [](int) { ros::requestShutdown(); });
  ros::NodeHandle pnh("~");
  clothwind::ros_bridge::StrictParams params(pnh);
  try {
    ClipReport report(params);
    params.WarnUnread("clip_report");
    ros::spin();
    return report.Finish() ? 0 : 1;  // Ctrl-C ends spin() before the timer printed: print now
  } catch (const std::exception& e) {
    clothwind::ros_bridge::RosFatal(std::string("clip_report: ") + e.what());
    return 1;
  }
}
