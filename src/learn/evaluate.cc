#include "learn/evaluate.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <fcntl.h>
#include <malloc.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "common/atomic_file.h"
#include "learn/dataset.h"
#include "learn/fly_direction.h"
#include "learn/predictor.h"

namespace clothwind::learn {
namespace fs = std::filesystem;

double CalibrationScale(const EvalResult& result) {
  const size_t n = result.truth.size();
  if (n == 0 || result.predicted.size() != n || result.predicted_std.size() != n) {
    throw std::invalid_argument("CalibrationScale: needs truth, predicted and predicted_std of one length >= 1");
  }
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!(result.predicted_std[i] > 0)) {
      const std::string name = i < result.names.size() ? result.names[i] : "example " + std::to_string(i);
      throw std::invalid_argument("CalibrationScale: predicted std of " + name + " is not positive");
    }
    const double z = (result.predicted[i] - result.truth[i]) / result.predicted_std[i];
    sum += z * z;
  }
  return std::sqrt(sum / n);
}

double StdCoverage(const EvalResult& result, double multiple) {
  // All three lengths, since all three are read: sized by truth and std alone, a shorter
  // `predicted` was read past its end.
  const size_t n = result.truth.size();
  if (n == 0 || result.predicted.size() != n || result.predicted_std.size() != n)
    return std::numeric_limits<double>::quiet_NaN();
  size_t within = 0;
  for (size_t i = 0; i < n; ++i) {
    within += std::abs(result.predicted[i] - result.truth[i]) <= multiple * result.predicted_std[i];
  }
  return static_cast<double>(within) / n;
}

Metrics ComputeMetrics(const std::vector<double>& truth, const std::vector<double>& predicted) {
  if (truth.size() != predicted.size()) throw std::invalid_argument("ComputeMetrics: sizes differ");
  Metrics m;
  m.count = static_cast<int>(truth.size());
  if (truth.empty()) {
    m.rmse = m.acc05 = m.bias = std::numeric_limits<double>::quiet_NaN();
    return m;
  }
  double se = 0, sum = 0;
  int within = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double e = predicted[i] - truth[i];
    se += e * e;
    sum += e;
    if (std::abs(e) <= 0.5) ++within;
  }
  m.rmse = std::sqrt(se / truth.size());
  m.acc05 = static_cast<double>(within) / truth.size();
  m.bias = sum / truth.size();
  return m;
}

std::vector<BandMetrics> ComputeBandMetrics(const std::vector<double>& truth, const std::vector<double>& predicted,
                                            double width) {
  if (truth.size() != predicted.size()) throw std::invalid_argument("ComputeBandMetrics: sizes differ");
  if (!(width > 0)) throw std::invalid_argument("ComputeBandMetrics: width must be > 0, got " + std::to_string(width));
  double top = 0;
  for (double t : truth) top = std::max(top, t);
  const int n = std::max(1, static_cast<int>(std::ceil(top / width)));
  std::vector<std::vector<double>> t(n), p(n);
  for (size_t i = 0; i < truth.size(); ++i) {
    const int b = std::clamp(static_cast<int>(std::floor(truth[i] / width)), 0, n - 1);
    t[b].push_back(truth[i]);
    p[b].push_back(predicted[i]);
  }
  std::vector<BandMetrics> bands(n);
  for (int b = 0; b < n; ++b) {
    bands[b].lo = b * width;
    bands[b].hi = (b + 1) * width;
    bands[b].metrics = ComputeMetrics(t[b], p[b]);
  }
  return bands;
}

SimulationMetrics ComputeSimulationMetrics(const std::vector<double>& truth, const std::vector<double>& predicted,
                                           const std::vector<int>& simulation) {
  if (truth.size() != predicted.size() || truth.size() != simulation.size()) {
    throw std::invalid_argument("ComputeSimulationMetrics: truth, predicted and simulation sizes differ");
  }
  struct Group {
    double truth = 0, sum = 0;
    int count = 0;
  };
  std::map<int, Group> groups;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (simulation[i] < 0) continue;
    Group& g = groups[simulation[i]];
    if (g.count > 0 && std::abs(g.truth - truth[i]) > 1e-9) {
      throw std::invalid_argument("ComputeSimulationMetrics: simulation " + std::to_string(simulation[i]) +
                                  " has clips of two winds, " + std::to_string(g.truth) + " and " +
                                  std::to_string(truth[i]) + " m/s");
    }
    g.truth = truth[i];
    g.sum += predicted[i];
    ++g.count;
  }
  SimulationMetrics m;
  m.simulations = static_cast<int>(groups.size());
  if (groups.empty()) {
    m.rmse = m.scatter = std::numeric_limits<double>::quiet_NaN();
    return m;
  }
  double se = 0, scatter = 0;
  for (const auto& [id, g] : groups) se += std::pow(g.sum / g.count - g.truth, 2);
  for (size_t i = 0; i < truth.size(); ++i) {
    if (simulation[i] < 0) continue;
    const Group& g = groups.at(simulation[i]);
    scatter += std::pow(predicted[i] - g.sum / g.count, 2);
    ++m.clips;
  }
  m.rmse = std::sqrt(se / groups.size());
  m.scatter = std::sqrt(scatter / m.clips);
  return m;
}

namespace {

// The distinct starts of `windows` evenly spaced windows of `frames` frames in `clip`
// (EvenWindowStarts; one: the centred window, as ChooseFirstFrame takes it).
// Throws std::runtime_error naming the clip when it is shorter than one window.
std::vector<int> ClipWindowStarts(const ClipInfo& clip, int frames, int windows) {
  try {
    return EvenWindowStarts(clip.num_frames, frames, windows);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(clip.name + ": " + e.what());
  }
}

}  // namespace

EvalResult Evaluate(const fs::path& model, const fs::path& data, const std::string& split, int threads,
                    const std::string& device, int batch, int windows, bool mirror, bool mirror_clips,
                    FlagFlies flag_flies, const std::function<void(int, int)>& progress,
                    const std::filesystem::path& fly_judge) {
  const auto start = std::chrono::steady_clock::now();
  if (windows < 1) throw std::invalid_argument("Evaluate: windows must be >= 1, got " + std::to_string(windows));
  Predictor predictor(model, threads, device);
  const Dataset dataset = ReadDataset(data);
  const std::vector<ClipInfo> clips = SelectSplit(dataset, split);
  if (clips.empty()) throw std::runtime_error((data / "index.json").string() + ": no examples in split " + split);
  EvalResult r;
  r.unlabelled = UnlabelledIn(dataset, split);
  r.config = predictor.config();
  r.device = predictor.device();
  CheckClipsSuitModel(clips, r.config.frame_rate, r.config.colour, r.config.frames);
  r.split = split;
  r.windows = windows;
  r.mirror = mirror;
  r.mirror_clips = mirror_clips;
  r.flag_flies = flag_flies;
  const int views = mirror ? 2 : 1;  // images read per window: it, and its mirror image
  SampleOptions options = r.config.Sampling();
  options.mirror_clip = mirror_clips;
  options.flag_flies = flag_flies;
  if (!fly_judge.empty()) predictor.LoadFlyJudge(fly_judge);
  options.fly_judge = predictor.fly_judge();
  if (flag_flies == FlagFlies::kAuto) {
    r.fly_judge = options.fly_judge ? predictor.fly_judge_path().string() : std::string("motion cues");
    // A judge beside the model that cannot be read: said, rather than falling back in silence.
    if (!options.fly_judge && !predictor.fly_judge_error().empty())
      r.fly_judge += " (the judge beside the model was not used: " + predictor.fly_judge_error() + ")";
  }
  batch = std::max(1, batch);
  r.windows_min = std::numeric_limits<int>::max();
  r.windows_max = 0;
  for (size_t i = 0; i < clips.size(); i += batch) {
    const size_t end = std::min(clips.size(), i + batch);
    // Each clip's own starts: a clip with little slack holds fewer distinct windows than asked.
    std::vector<std::vector<int>> starts;
    size_t most = 0;
    for (size_t j = i; j < end; ++j) {
      starts.push_back(ClipWindowStarts(clips[j], options.frames, windows));
      most = std::max(most, starts.back().size());
    }
    std::vector<double> sum(end - i, 0.0), sum_var(end - i, 0.0);
    for (size_t w = 0; w < most; ++w) {
      for (int view = 0; view < views; ++view) {
        std::vector<Sample> samples;
        std::vector<size_t> of;  // the batch's clip each sample shows
        for (size_t j = i; j < end; ++j) {
          if (w >= starts[j - i].size()) continue;
          SampleOptions o = options;
          o.mirror = view == 1;
          o.first_frame = starts[j - i][w];
          samples.push_back(LoadSample(clips[j], o, 0));
          of.push_back(j - i);
        }
        std::vector<const Sample*> pointers;
        for (const Sample& s : samples) pointers.push_back(&s);
        const std::vector<Prediction> predictions = predictor.Predict(pointers);
        if (view == 0) {
          for (const Sample& sample : samples) {
            r.turned += sample.turned;
            r.undecided += sample.undecided;
          }
        }
        for (size_t k = 0; k < samples.size(); ++k) {
          sum[of[k]] += predictions[k].raw_speed;  // averaged as the network gave them, then clamped
          sum_var[of[k]] += predictions[k].speed_std * predictions[k].speed_std;
        }
      }
    }
    for (size_t j = i; j < end; ++j) {
      const int used = static_cast<int>(starts[j - i].size());
      const int passes = used * views;
      r.windows_min = std::min(r.windows_min, used);
      r.windows_max = std::max(r.windows_max, used);
      r.windows_read += used;
      r.names.push_back(clips[j].name);
      r.dirs.push_back(clips[j].dir);
      r.truth.push_back(clips[j].wind_speed);
      r.simulations.push_back(clips[j].simulation);
      r.predicted.push_back(ClampSpeed(sum[j - i] / passes));
      r.predicted_std.push_back(std::sqrt(sum_var[j - i] / passes));
    }
    if (progress) progress(static_cast<int>(r.truth.size()), static_cast<int>(clips.size()));
    // Hand the batch's freed pages back to the system. Without this glibc's heap kept them:
    // evaluating 1228 clips of 128-px frames peaked at 9.0 GB resident (7 MB a clip), and e5's
    // 4792 test clips were killed for memory; with it the peak is 0.37 GB at the same speed.
    ::malloc_trim(0);
  }
  r.metrics = ComputeMetrics(r.truth, r.predicted);
  r.bands = ComputeBandMetrics(r.truth, r.predicted, kEvalBandWidth);
  r.per_simulation = ComputeSimulationMetrics(r.truth, r.predicted, r.simulations);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

namespace {
// An empty group has no figures: null, not NaN (which JSON lacks).
nlohmann::json Number(double x) { return std::isnan(x) ? nlohmann::json(nullptr) : nlohmann::json(x); }

// CalibrationScale, NaN where it has nothing to fit (no stds, lists of other lengths, or a std
// that is not positive: each of which it refuses).
double CalibrationScaleOrNaN(const EvalResult& r) {
  try {
    return CalibrationScale(r);
  } catch (const std::invalid_argument&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}
}  // namespace

nlohmann::json MetricsJson(const Metrics& m) {
  return {{"rmse", Number(m.rmse)}, {"acc05", Number(m.acc05)}, {"bias", Number(m.bias)}, {"count", m.count}};
}

nlohmann::json EvalJson(const EvalResult& r) {
  nlohmann::json bands = nlohmann::json::array();
  for (const BandMetrics& b : r.bands) {
    nlohmann::json band = {{"lo", b.lo}, {"hi", b.hi}};
    band.update(MetricsJson(b.metrics));
    bands.push_back(band);
  }
  return {{"rmse", r.metrics.rmse},   {"acc05", r.metrics.acc05}, {"count", r.metrics.count},
          {"model", r.config.Name()}, {"arch", r.config.arch},    {"modality", r.config.Modality()},
          {"split", r.split},         {"windows", r.windows},
          {"windows_used", {{"min", r.windows_min}, {"max", r.windows_max}, {"total", r.windows_read}}},
          {"device", r.device.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.device)},
          {"mirror", r.mirror},
          {"mirror_clips", r.mirror_clips}, {"flag_flies", FlagFliesName(r.flag_flies)}, {"turned", r.turned},
          {"undecided", r.undecided},
          {"fly_judge", r.fly_judge.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.fly_judge)},
          {"seconds", r.seconds},
          {"std_within_1", Number(StdCoverage(r, 1))}, {"std_within_2", Number(StdCoverage(r, 2))},
          {"std_scale_fit", Number(CalibrationScaleOrNaN(r))},
          {"bands", bands},
          {"per_simulation", r.per_simulation.simulations == 0
                                 ? nlohmann::json(nullptr)
                                 : nlohmann::json{{"rmse", r.per_simulation.rmse},
                                                  {"scatter", r.per_simulation.scatter},
                                                  {"simulations", r.per_simulation.simulations},
                                                  {"clips", r.per_simulation.clips}}}};
}

namespace {

// EvalTable's words for the windows a result with windows > 1 averaged, e.g. ", mean of 3 frame
// windows per clip"; the count of each clip's distinct windows when it is not what was asked.
std::string WindowsUsed(const EvalResult& r) {
  std::ostringstream s;
  if (r.windows_min == r.windows && r.windows_max == r.windows) {
    s << ", mean of " << r.windows << " frame windows per clip";
  } else {
    s << ", mean of " << r.windows_min;
    if (r.windows_max != r.windows_min) s << " to " << r.windows_max;
    s << " distinct frame window" << (r.windows_max == 1 ? "" : "s") << " per clip, not the " << r.windows
      << " asked for: " << (r.windows_max == r.windows_min ? "the clips hold no more" : "shorter clips hold fewer");
  }
  return s.str();
}

}  // namespace

std::string EvalTable(const EvalResult& r) {
  std::ostringstream s;
  const std::string model = r.config.arch == "sdn"    ? "SDN"
                            : r.config.arch == "lstm" ? "Yang et al."
                                                      : "ResNet-18";
  const std::string name = model + " (" + r.config.Name() + ")";
  const int width = std::max<int>(28, static_cast<int>(name.size()) + 2);
  s << std::left << std::setw(width) << "Model" << std::setw(18) << "Input Modality" << std::setw(10) << "RMSE"
    << "Acc@0.5\n";
  s << std::setw(width) << name << std::setw(18) << r.config.Modality()
    << std::setw(10) << std::fixed << std::setprecision(3) << r.metrics.rmse << r.metrics.acc05 << "\n";
  s << "(" << r.metrics.count << " examples, split " << r.split;
  // Said only off the CPU, where the figures can differ (cuDNN's algorithms): the CPU's table stays
  // as it was.
  if (!r.device.empty() && r.device != "cpu") s << ", on " << r.device;
  if (r.unlabelled > 0) s << "; " << r.unlabelled << " recorded clips without a wind label left out";
  if (r.windows > 1) s << WindowsUsed(r);
  if (r.mirror) s << ", each averaged with its mirror image";
  if (r.mirror_clips) s << ", clips mirrored (flags flying left)";
  if (r.flag_flies == FlagFlies::kLeft) s << ", every clip turned round (--flag-flies left)";
  if (r.flag_flies == FlagFlies::kAuto) {
    s << ", turned round by " << (r.fly_judge.rfind("motion cues", 0) == 0 ? "their motion" + r.fly_judge.substr(11)
                                                                : "the judge " + r.fly_judge) << ": "
      << r.turned << " of " << r.windows_read << " windows";
    if (r.undecided > 0) s << ", " << r.undecided << " it could not tell read as filmed";
  }
  s << ")\n";
  if (!r.predicted_std.empty()) {
    s << "  predicted std: errors within 1 std " << StdCoverage(r, 1) << ", within 2 std " << StdCoverage(r, 2)
      << " (calibrated: 0.683, 0.954); std scale that calibrates it on these clips "
      << CalibrationScaleOrNaN(r) << "\n";
  }
  for (const BandMetrics& b : r.bands) {
    if (b.metrics.count == 0) continue;
    s << std::setprecision(0) << "  true " << std::right << std::setw(2) << b.lo << "-" << std::left << std::setw(2)
      << b.hi << " m/s: RMSE " << std::setprecision(3) << b.metrics.rmse << "  Acc@0.5 " << b.metrics.acc05
      << "  bias " << std::showpos << b.metrics.bias << std::noshowpos << "  (" << b.metrics.count << ")\n";
  }
  const SimulationMetrics& ps = r.per_simulation;
  if (ps.simulations > 0) {
    s << std::setprecision(3) << "  per simulation (mean of its clips): RMSE " << ps.rmse << "; views scatter "
      << ps.scatter << "  (" << ps.simulations << " simulations, " << ps.clips << " clips)\n";
  }
  return s.str();
}

namespace {

// `text` as a gnuplot string in single quotes (where '' stands for one ').
std::string GnuplotQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// Runs `body` (which writes files and may throw): a plot that cannot be written is reported
// through `error`, never thrown, so the results it would illustrate are kept.
template <typename F>
bool Plotting(std::string* error, F body) {
  try {
    return body();
  } catch (const std::exception& e) {
    if (error) *error = e.what();
    return false;
  }
}

}  // namespace

bool RunGnuplot(const std::string& script, const fs::path& png, std::string* error) {
  return Plotting(error, [&] {
  // "<png>.tmp-<tag>-<n>" (TemporaryNameFor; a run's --overwrite clears it too). Those of runs that
  // stopped while gnuplot drew go first: a killed run's stayed beside every later curve, resumes
  // included.
  RemoveStaleTemporariesOf(png.string());
  const std::string tmp = TemporaryNameFor(png.string());
  const fs::path script_path = png.string() + ".gp";
  WriteFileAtomically(script_path, "set terminal pngcairo size 800,600 noenhanced\nset output " + GnuplotQuoted(tmp) +
                                       "\n" + script);
  // Started directly, not through std::system: system() ignores SIGINT and SIGQUIT in its caller
  // while the child runs, and gnuplot catches a Ctrl-C and exits 1, so the Ctrl-C was lost (train
  // ran on to its last epoch and exited 0). Here the caller keeps its own handling of it.
  const std::string err_path = script_path.string() + ".err";
  int rc = -1;  // wait status; -1: not started
  std::string start_error;
  {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    std::string arg0 = "gnuplot", arg1 = script_path.string();
    char* argv[] = {arg0.data(), arg1.data(), nullptr};
    pid_t pid = -1;
    const int spawned = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) {
      start_error = std::strerror(spawned);
    } else {
      int status = 0;
      pid_t waited;
      do {
        waited = ::waitpid(pid, &status, 0);
      } while (waited < 0 && errno == EINTR);
      if (waited == pid) rc = status;
      else start_error = std::string("waitpid: ") + std::strerror(errno);
    }
  }
  if (rc != 0 || !fs::exists(tmp)) {
    // The wait status itself ("exit 2" was signal 2, SIGINT).
    const std::string how = rc == -1            ? "could not be started: " + start_error + "; is it on PATH?"
                            : WIFSIGNALED(rc)   ? "ended by signal " + std::to_string(WTERMSIG(rc))
                            : WIFEXITED(rc)     ? "exit " + std::to_string(WEXITSTATUS(rc))
                                                : "status " + std::to_string(rc);
    if (error) *error = "gnuplot failed (" + how + ")" + (rc == -1 ? "" : ", see " + err_path);
    fs::remove(tmp);
    return false;
  }
  std::error_code ec;
  fs::rename(tmp, png, ec);
  if (ec) {  // e.g. a folder of that name: the finished temporary must not stay behind
    if (error) *error = "cannot write " + png.string() + ": " + ec.message();
    fs::remove(tmp, ec);
    return false;
  }
  fs::remove(script_path.string() + ".err");
  return true;
  });
}

std::string EvalProtocol(int windows, bool mirror, bool mirror_clips, const std::string& flag_flies) {
  return "windows " + std::to_string(windows) + " mirror " + (mirror ? "1" : "0") + " mirror_clips " +
         (mirror_clips ? "1" : "0") + " flag_flies " + flag_flies;
}

std::string EvalProtocol(const EvalResult& r) {
  return EvalProtocol(r.windows, r.mirror, r.mirror_clips, FlagFliesName(r.flag_flies));
}

std::string EvalProtocolSuffix(int windows, bool mirror, bool mirror_clips, const std::string& flag_flies) {
  std::string suffix;
  if (windows != 1) suffix += "_w" + std::to_string(windows);
  if (mirror) suffix += "_mirror";
  if (mirror_clips) suffix += "_mirrored";
  if (flag_flies != "right") suffix += "_flies-" + flag_flies;
  return suffix;
}

bool PlotPredictions(const EvalResult& r, const fs::path& png, std::string* error) {
  return Plotting(error, [&] {
  const fs::path data = png.string() + ".dat";
  const std::string protocol = EvalProtocol(r);
  // Table 1's reading is one centred window of each clip as filmed; any other says so, in the
  // title and the data file (scripts/compare-evals refuses to pair two protocols).
  const bool table1 = protocol == EvalProtocol(1, false, false, "right");
  std::ostringstream d;
  d << "# protocol " << protocol << "\n# true_speed predicted_speed predicted_std name\n" << std::setprecision(6);
  for (size_t i = 0; i < r.truth.size(); ++i) {
    d << r.truth[i] << " " << r.predicted[i] << " " << r.predicted_std[i] << " " << r.names[i] << "\n";
  }
  WriteFileAtomically(data, d.str());
  double hi = 1;
  for (size_t i = 0; i < r.truth.size(); ++i) hi = std::max({hi, r.truth[i], r.predicted[i]});
  hi = std::ceil(hi + 0.5);
  std::ostringstream s;
  s << std::setprecision(4) << "set title '" << r.config.Name() << " on " << r.split << ": RMSE "
    << r.metrics.rmse << " m/s, Acc@0.5 " << r.metrics.acc05 << " (" << r.metrics.count << ")"
    << (table1 ? "" : "; " + protocol) << "'\n"
    << "set xlabel 'true wind speed [m/s]'\nset ylabel 'predicted wind speed [m/s]'\n"
    << "set xrange [0:" << hi << "]\nset yrange [0:" << hi << "]\nset size square\nset key top left\nset grid\n"
    << "plot x+0.5 with lines dt 2 lc 'grey' title '±0.5 m/s', x-0.5 with lines dt 2 lc 'grey' notitle, "
    << "x with lines lc 'black' title 'ideal', " << GnuplotQuoted(data.string())
    << " using 1:2:3 with yerrorbars pt 7 ps 0.5 lc 'blue' title 'prediction ± std'\n";
  return RunGnuplot(s.str(), png, error);
  });
}

bool PlotLearningCurve(const std::vector<EpochRecord>& log, const fs::path& png, std::string* error,
                       const std::string& validated_on) {
  return Plotting(error, [&] {
  const fs::path data = png.string() + ".dat";
  std::ostringstream d;
  d << "# epoch train_rmse val_rmse train_loss val_loss raw_val_rmse\n";
  bool averaged = false;  // a run with a weight average also draws its trained weights' validation
  for (const EpochRecord& e : log) {
    d << e.epoch << " " << e.train_rmse << " " << e.val_rmse << " " << e.train_loss << " " << e.val_loss << " "
      << e.raw_val_rmse << "\n";
    averaged = averaged || e.raw_val_rmse > 0;
  }
  WriteFileAtomically(data, d.str());
  // A run without a val split validates on train: its curve said "validation RMSE" all the same.
  const std::string val = validated_on == "val" ? "validation RMSE" : "RMSE on " + validated_on;
  std::ostringstream s;
  s << "set title 'learning curve'\nset xlabel 'epoch'\nset ylabel 'RMSE [m/s]'\nset grid\nset key top right\n"
    << "plot " << GnuplotQuoted(data.string()) << " using 1:2 with linespoints title 'train RMSE', '' using 1:3 with "
    << "linespoints title '" << (averaged ? val + " (weight average)" : val) << "'";
  if (averaged) s << ", '' using 1:6 with linespoints title '" << val << " (trained weights)'";
  s << "\n";
  return RunGnuplot(s.str(), png, error);
  });
}

}  // namespace clothwind::learn
