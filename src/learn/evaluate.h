// Evaluation of a wind network in Table 1's terms (RMSE, Acc@0.5) and the plots of training
// and evaluation (gnuplot PNGs).
#ifndef CLOTHWIND_LEARN_EVALUATE_H_
#define CLOTHWIND_LEARN_EVALUATE_H_

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "learn/model_config.h"

namespace clothwind::learn {

struct Metrics {
  double rmse = 0;   // [m/s] root mean squared error
  double acc05 = 0;  // fraction of examples with |pred - true| <= 0.5 m/s
  double bias = 0;   // [m/s] mean of pred - true
  int count = 0;
};

// Table 1's metrics of predictions against labels (same length; empty gives count 0, NaNs).
Metrics ComputeMetrics(const std::vector<double>& truth, const std::vector<double>& predicted);

// Table 1's metrics and the bias of the examples whose true speed lies in [lo, hi): where over
// the speed range a model errs, and which way (a regression falls back towards the label mean at
// the ends of the range, so the top band's bias is negative).
struct BandMetrics {
  double lo = 0, hi = 0;  // [m/s] true speed range [lo, hi); the last band also holds hi itself
  Metrics metrics;        // NaN figures when the band is empty
};

// Splits [0, top] into bands of `width` m/s, top = width * ceil(max truth / width) (at least one
// band), and returns every band's metrics in order, empty bands included (count 0, NaNs).
// Inputs: truth, predicted  [n] m/s, same length; width > 0 [m/s].
// Throws std::invalid_argument for sizes that differ or width <= 0.
std::vector<BandMetrics> ComputeBandMetrics(const std::vector<double>& truth, const std::vector<double>& predicted,
                                            double width);

// How a split's error divides between what the clips of one simulation share and how they scatter
// around it. A FlagSim simulation is seen by several cameras (views), each its own clip with the
// simulation's one wind: an error every view makes is in the simulation (its flag's motion, its
// material), one that changes from view to view is in the camera.
struct SimulationMetrics {
  double rmse = 0;     // [m/s] rms over simulations of (mean prediction of its clips - its wind)
  double scatter = 0;  // [m/s] rms over clips of (prediction - its simulation's mean prediction)
  int simulations = 0;
  int clips = 0;       // clips from a simulation (those with simulation id -1 are left out)
};

// Inputs: truth, predicted [n] m/s; simulation [n] each clip's simulation id (>= 0), or -1 for a
//         clip from no simulation (a recorded one), which is left out.
// Output: the metrics above; NaN rmse and scatter when no clip has an id. When every simulation
//         has the same number of clips, rmse^2 + scatter^2 is the clips' mean squared error.
// Throws std::invalid_argument for sizes that differ, or for clips of one simulation whose truths
// differ (a simulation has one wind).
SimulationMetrics ComputeSimulationMetrics(const std::vector<double>& truth, const std::vector<double>& predicted,
                                           const std::vector<int>& simulation);

// Width of the speed bands `clothwind eval` reports [m/s]: five bands over FlagSim's 0-10 m/s.
inline constexpr double kEvalBandWidth = 2.0;

struct EvalResult {
  ModelConfig config;
  std::string split;
  std::vector<std::string> names;
  std::vector<std::filesystem::path> dirs;  // each example's folder (frames, label.json)
  std::vector<double> truth, predicted, predicted_std;  // [m/s]
  std::vector<int> simulations;  // each clip's simulation id (ClipInfo::simulation; -1: none)
  // Recorded clips of this split left out: no wind label (UnlabelledIn; other splits' not counted).
  size_t unlabelled = 0;
  std::string device;   // where the network ran: "cpu" or "cuda" (Predictor::device; "" unset)
  int windows = 1;      // frame windows asked for per clip (eval --windows; the protocol's)
  // The distinct windows each clip was read at, fewest and most over the clips, and their sum:
  // fewer than `windows` for a clip with less than windows - 1 frames of slack (EvenWindowStarts).
  int windows_min = 1, windows_max = 1, windows_read = 0;
  bool mirror = false;  // each window averaged with its mirror image
  bool mirror_clips = false;  // every clip mirrored first, as if its flag flew left
  FlagFlies flag_flies = FlagFlies::kRight;  // how each clip was turned before the model read it
  int turned = 0;  // windows that flag_flies turned round (mirrored: their flag flew left)
  int undecided = 0;  // windows the fly judge could not tell (read as filmed: eval's clips are apart)
  // With flag_flies kAuto: the judge's file, or "motion cues" without one (empty otherwise).
  std::string fly_judge;
  Metrics metrics;
  std::vector<BandMetrics> bands;  // by true speed, kEvalBandWidth wide
  SimulationMetrics per_simulation;  // simulations == 0 for a dataset without simulation ids
  double seconds = 0;  // wall time of the evaluation
};

// Evaluates the model (model.pt + model.json) over one split of a dataset with the evaluation
// preprocessing (centred frame window, centred square crop, no flip).
// Inputs: threads  torch threads; device  cpu|cuda|auto; batch  clips per forward pass;
//         windows  frame windows per clip (EvenWindowStarts; 1: the centred one, Table 1's
//                  protocol; a clip with too little slack for that many distinct ones is read at
//                  those it has, each once: EvalResult::windows_min): the clip's prediction is
//                  their mean speed and its std the root mean of their variances (not divided by
//                  the count: the windows show one flag, so their errors are not independent);
//         mirror   also predict each window's mirror image (horizontal flip, as training's
//                  augmentation: a flag seen from the other side) and average the two the same way;
//         mirror_clips  mirror every clip before anything else (SampleOptions::mirror_clip): FlagSim's
//                  flags all fly right, so this is how a model reads flags that fly left;
//         flag_flies  how each clip is then turned round (SampleOptions::flag_flies; kRight: as it
//                  comes, the default here whatever the model, so that figures stay comparable);
//         progress  called after each batch with (done, total) (may be empty);
//         fly_judge  with kAuto, the judge that decides (FlyJudge::Load); empty: the one beside the
//                  model (Predictor::fly_judge), or the motion cues when there is none.
EvalResult Evaluate(const std::filesystem::path& model, const std::filesystem::path& data, const std::string& split,
                    int threads, const std::string& device, int batch, int windows = 1, bool mirror = false,
                    bool mirror_clips = false, FlagFlies flag_flies = FlagFlies::kRight,
                    const std::function<void(int, int)>& progress = {},
                    const std::filesystem::path& fly_judge = {});

// {"rmse", "acc05", "bias", "count"} of one group of examples; NaN figures (an empty group) as null.
nlohmann::json MetricsJson(const Metrics& metrics);

// {"rmse": …, "acc05": …, "count": …} plus the model, split, windows (asked for), "windows_used"
// ({"min", "max", "total"}: the distinct windows read per clip, and over all clips), "device"
// ("cpu" or "cuda"; null unset), mirror, mirror_clips,
// flag_flies, turned, fly_judge (null unless flag_flies is auto), "bands" (a list of
// {"lo", "hi", "rmse", "acc05", "bias", "count"}; NaNs of empty bands as null) and
// "per_simulation" ({"rmse", "scatter", "simulations", "clips"}; null without simulation ids),
// "std_within_1", "std_within_2" (StdCoverage) and "std_scale_fit" (CalibrationScale: the factor
// export-model --calibrate-std would apply, fitted on these clips read this way); each null
// without predicted stds.
nlohmann::json EvalJson(const EvalResult& result);

// Table 1's layout: header and one row ("Model  Input Modality  RMSE  Acc@0.5"), a line of how
// the clips were read (count, split, the device when not the CPU, windows, ...), then one line
// per non-empty speed band (RMSE, Acc@0.5, bias, count) and one for the per-simulation split.
std::string EvalTable(const EvalResult& result);

// How an evaluation read its clips, in words a file can carry: "windows 1 mirror 0 mirror_clips 0
// flag_flies right" is Table 1's reading (one centred window, as filmed).
// Inputs: the eval options of the same names (flag_flies: "right", "left" or "auto").
std::string EvalProtocol(int windows, bool mirror, bool mirror_clips, const std::string& flag_flies);
// The same, of a result.
std::string EvalProtocol(const EvalResult& result);
// A file-name suffix that tells an evaluation read otherwise from Table 1's ("" for Table 1's;
// e.g. "_w3_mirror" for three windows, each with its mirror image), so that eval's default plot
// of one protocol does not replace another's.
std::string EvalProtocolSuffix(int windows, bool mirror, bool mirror_clips, const std::string& flag_flies);

// Predicted against true wind speed, with the identity line and ±0.5 m/s band, as a PNG via
// gnuplot (written atomically), and beside it <png>.dat: a "# protocol ..." line (EvalProtocol),
// then true speed, predicted speed, predicted std and clip name per line. The title names the
// protocol when it is not Table 1's. Returns false (and says why in *error) if gnuplot fails.
bool PlotPredictions(const EvalResult& result, const std::filesystem::path& png, std::string* error);

// The factor k by which predicted standard deviations must be multiplied so that the errors,
// measured in them, have unit root mean square: k = sqrt(mean(((predicted - truth) / std)^2)).
// k > 1: the model is over-confident. Fitted on a validation split, it calibrates the std
// (ModelConfig::std_scale) without touching the speeds.
// Inputs: result  truth, predicted, predicted_std [n] (std > 0), n >= 1.
// Throws std::invalid_argument for an empty result or a std that is not positive.
double CalibrationScale(const EvalResult& result);

// Fraction of the examples whose error is at most `multiple` predicted stds (a calibrated
// Gaussian std gives 0.683 at 1 and 0.954 at 2). Inputs as CalibrationScale; NaN when empty or
// when truth, predicted and predicted_std differ in length (a result without stds).
double StdCoverage(const EvalResult& result, double multiple);

// One line of the training log per epoch.
struct EpochRecord {
  int epoch = 0;
  double lr = 0;
  double train_loss = 0, val_loss = 0;  // WindLoss, normalised units
  double train_rmse = 0, val_rmse = 0;  // [m/s]
  double val_acc05 = 0;
  double seconds = 0;                   // wall time of the epoch
  double train_aux_loss = 0;            // AuxLoss over the epoch (0 without auxiliary targets)
  // With a weight average (TrainOptions::weight_average), val_rmse is the average's and this the
  // trained weights' own [m/s]; 0 without one.
  double raw_val_rmse = 0;
  // Where the epoch trained: "cpu" or "cuda", and torch's intra-op threads. A resumed run repeats
  // the uninterrupted one exactly only on the same device with as many threads, so a resume on
  // another machine shows in the log ("" and 0 in runs from before stop 74).
  std::string device;
  int threads = 0;
};

// Training and validation RMSE per epoch as a PNG via gnuplot (atomically).
bool PlotLearningCurve(const std::vector<EpochRecord>& log, const std::filesystem::path& png, std::string* error,
                       const std::string& validated_on = "val");

// Runs a gnuplot script that writes `png`; the script and data are written next to it.
bool RunGnuplot(const std::string& script, const std::filesystem::path& png, std::string* error);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_EVALUATE_H_
