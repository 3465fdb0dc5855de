// Inference with a saved wind network, behind a torch-free interface (pimpl) so the node, the
// eval verb and the bench need no torch headers.
#ifndef CLOTHWIND_LEARN_PREDICTOR_H_
#define CLOTHWIND_LEARN_PREDICTOR_H_

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "learn/dataset.h"
#include "learn/model_config.h"

namespace clothwind::learn {

struct Prediction {
  // [m/s], never below 0: the network's output, a regression, dips below 0 for some calm clips
  // (wind speed cannot), and 0 is nearer the truth than any negative value. NaN stays NaN.
  double speed = 0;
  // [m/s] the network's output before that clamp. What an average of several predictions adds
  // up (eval's windows, sdn_node's trailing mean), clamping only the average: the mean of
  // clamped values is biased up for calm clips (E[max(X, 0)] > max(E[X], 0)).
  double raw_speed = 0;
  double speed_std = 0;  // [m/s] predicted standard deviation (the network's uncertainty)
  bool turned = false;   // PredictFrames mirrored the clip first: its flag flies left (flag_flies())
  bool undecided = false;  // with flag_flies auto: the judge could not tell; the last way it knew was kept
  // [grey levels, 0..255] the clip's motion (ClipMotion of the frames read), measured before the
  // per-clip normalisation, which stretches any residue to unit spread.
  double motion = 0;
  // motion below kMinClipMotion: every frame the same (a frozen camera, a driver republishing its
  // last frame; a constant image). The network still answers, with a std like a live clip's (a
  // repeated FlagSim frame read 5-7 m/s ± 0.4, a constant image 1.2 ± 0.2): callers must not take
  // it as a measurement.
  bool no_motion = false;
  // [grey levels] the clip's picture contrast (ClipContrast of the frames read).
  double contrast = 0;
  // contrast below kMinClipContrast: the frames show no scene, only noise or one level (a covered
  // lens, a camera in the dark, a flat field of fog). The network answers sensor noise with some
  // wind; callers must not take it as a measurement.
  bool no_scene = false;
};

// [grey levels] Below this mean temporal spread a clip's frames are all the same (a frozen camera:
// 0 but for rounding). Not a noise floor: a live still scene's noise, once the clip buffer has
// shrunk a 1080 px camera to 300 px and rounded to 8 bits, is 0.14-0.2 grey levels, and a small or
// limp flag's motion is as little averaged over the frame; those are estimated.
inline constexpr double kMinClipMotion = 0.01;

// The motion of a clip: the mean over its pixels of each pixel's standard deviation over time, in
// grey levels, of the frames' first channel (grey, or Y of YCrCb).
// Inputs: frames  at least one, 8-bit, one size (1 or 3 channels).
// Returns it (0 for identical frames).
double ClipMotion(const std::vector<cv::Mat>& frames);

// [grey levels] Below this a clip's picture is flat: no flag, pole or horizon, noise alone. Why
// 1: a 9 x 9 box blur leaves 1/9 of a pixel's noise, so sensor noise up to ~9 grey levels a pixel
// reads under it, where a flag against the sky spreads over tens (a faint flag in thick fog, a few
// grey levels from it, may not: it is not estimated).
inline constexpr double kMinClipContrast = 1.0;

// The contrast of a clip: its frames' spatial standard deviation after a 9 x 9 box blur (which
// averages pixel noise away and keeps the scene's shapes), in grey levels, the largest over the
// channels (a colour clip's red flag against green may share one grey), the mean over every
// fifth frame (the scene does not change within a clip). Not caught: noise past ~9 grey levels a
// pixel (a dark camera at full gain), a timestamp or logo burned into the dark frame, a light
// leak's or a vignette's gradient across a covered lens (each a scene to this measure).
// Inputs: frames  at least one, 8-bit, one size (1 or 3 channels).
// Returns it (0, to rounding, for a uniform picture, however it flickers).
double ClipContrast(const std::vector<cv::Mat>& frames);

// The strongest spectral peak of every pixel of a clip (SDN models only), at input resolution.
struct PeakMaps {
  cv::Mat power;      // CV_32F input_size x input_size, periodogram of the strongest bin
  cv::Mat frequency;  // CV_32F input_size x input_size, its frequency [Hz]
};

// A wind speed estimate as published: `raw` [m/s] clamped at 0 from below, NaN kept (callers refuse
// it; std::max would turn it into 0).
inline double ClampSpeed(double raw) { return raw < 0 ? 0.0 : raw; }

class Predictor {
 public:
  // Inputs:
  //   weights  a model saved by training (model.pt with model.json beside it)
  //   threads  torch intra-op threads (process-wide setting)
  //   device   "cpu", "cuda" (error when absent) or "auto" (CUDA when libtorch finds one); on
  //            CUDA, TF32 is turned off process-wide (full float32, as on the CPU)
  //   channels_last  on the CPU, run the convolutions in channels-last order (UseChannelsLast:
  //            ~10 % faster, the same predictions to float rounding); false keeps torch's
  //            default order (bench/sdn_bench --both-orders measures the difference)
  // Throws std::runtime_error naming the file when the model cannot be loaded.
  Predictor(const std::filesystem::path& weights, int threads, const std::string& device,
            bool channels_last = true);
  ~Predictor();
  Predictor(const Predictor&) = delete;
  Predictor& operator=(const Predictor&) = delete;

  const ModelConfig& config() const;
  std::string device() const;  // "cpu" or "cuda"

  // How PredictFrames and Prepare turn a clip before the model reads it (fly_direction.h):
  // config().DefaultFlagFlies() until set (auto for a model trained without flips, as filmed
  // otherwise). The node's ~flag_flies sets it.
  FlagFlies flag_flies() const { return flag_flies_; }
  void set_flag_flies(FlagFlies flag_flies) { flag_flies_ = flag_flies; }

  // The judge flag_flies auto asks (SampleOptions::fly_judge): the one in kFlyJudgeFile beside
  // the weights when there is one (models/fly_judge.pt beside models/sdn.pt), else none (the
  // clip's motion cues). fly_judge_path() is its file, empty for none. A judge beside the weights
  // that cannot be read does not stop the model: the constructor leaves none and says why in
  // fly_judge_error() (empty when there was nothing to say), for the caller to report.
  const std::shared_ptr<const FlyJudge>& fly_judge() const { return fly_judge_; }
  const std::filesystem::path& fly_judge_path() const { return fly_judge_path_; }
  const std::string& fly_judge_error() const { return fly_judge_error_; }
  // Loads another judge (FlyJudge::Load; empty: none, the motion cues) and clears
  // fly_judge_error(). Throws as FlyJudge::Load, leaving the judge before it.
  void LoadFlyJudge(const std::filesystem::path& path);

  // Predictions for prepared samples (each config().channels x config().frames x input_size²
  // floats, as MakeSample makes them), in one batch. Throws std::invalid_argument naming the
  // sample of another size.
  std::vector<Prediction> Predict(const std::vector<const Sample*>& samples);

  // A raw greyscale clip as a node receives it: the last config().frames frames, centred square
  // crop, resized and normalised as for evaluation. With flag_flies auto a clip the judge cannot
  // tell (a calm spell) is turned as the last clip it could tell was, as filmed until one was: a
  // stream of clips keeps its flag's side instead of a coin's for each. `maps` (may be null; SDN only) receives the
  // strongest peak maps of the same input, oriented as the frames given (a clip turned round for
  // the model has its maps turned back).
  // Throws std::invalid_argument when there are too few frames or they are not equal CV_8UC1
  // (CV_8UC3 YCrCb, LoadFrames' colour frames, for a model with config().colour).
  Prediction PredictFrames(const std::vector<cv::Mat>& frames, PeakMaps* maps = nullptr);

  // A clip with the evaluation preprocessing (no augmentation) from raw greyscale (or YCrCb)
  // frames, turned as flag_flies() says (Sample::turned; a clip the judge cannot tell as the last
  // one PredictFrames saw it tell).
  Sample Prepare(const std::vector<cv::Mat>& frames) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  FlagFlies flag_flies_ = FlagFlies::kRight;
  bool last_turned_ = false;  // the way the judge last told (PredictFrames), for clips it cannot
  std::shared_ptr<const FlyJudge> fly_judge_;
  std::filesystem::path fly_judge_path_;
  std::string fly_judge_error_;
};

// The judge's file name a Predictor looks for beside its weights.
inline constexpr const char* kFlyJudgeFile = "fly_judge.pt";

// A false-colour BGR image of `value` (CV_32F) scaled from [lo, hi] to OpenCV colour map
// `colormap` (e.g. cv::COLORMAP_INFERNO); values outside are clamped.
cv::Mat ColourMapped(const cv::Mat& value, double lo, double hi, int colormap);

// Pixels whose strongest peak holds under this fraction of the frame's strongest: their frequency
// is noise's (still sky, the backdrop), left black in the frequency image.
inline constexpr double kFrequencyMapPowerFraction = 0.01;

// The frequency map as rviz shows it (sdn/frequency): jet from 0 to `nyquist` [Hz], black where
// the peak's power is under kFrequencyMapPowerFraction of the map's strongest (all of it painted,
// a still sky read as 8.33 Hz and the camera's noise as anything).
// Inputs: maps  power and frequency of one size (PeakMaps); nyquist  the top of the scale [Hz].
// Returns a BGR image of the maps' size.
cv::Mat FrequencyMapImage(const PeakMaps& maps, double nyquist);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_PREDICTOR_H_
