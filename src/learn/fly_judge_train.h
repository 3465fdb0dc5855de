// Training and measuring the fly-direction judge (fly_judge.h) on a dataset's clips: clothwind
// train-fly-judge. Every FlagSim flag flies right, and the judge's score is antisymmetric under
// mirroring, so training it to call each clip "right" trains it to call each mirror image "left".
#ifndef CLOTHWIND_LEARN_FLY_JUDGE_TRAIN_H_
#define CLOTHWIND_LEARN_FLY_JUDGE_TRAIN_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "learn/dataset.h"
#include "learn/fly_judge.h"

namespace clothwind::learn {

// Motion maps of windows of a dataset's clips, each with its clip's wind speed.
struct MotionMaps {
  std::vector<cv::Mat> maps;         // MotionMap (kMotionMapGrid² CV_32FC1) of each window
  std::vector<double> wind_speeds;   // [m/s] the window's clip's label
};

// Inputs:
//   clips     examples (SelectSplit); each must have at least `frames` frames
//   frames    window length (a model's frames, 30)
//   windows   evenly spaced windows per clip (EvenWindowStarts; 1: the centred one, as eval reads)
//   progress  called after each clip with (done, total) (may be empty)
// Returns clips.size() * windows maps (fewer where a clip holds fewer distinct windows:
// EvenWindowStarts), clip by clip: each window's centred square, as a model
// reads it, through MotionMap. Throws as LoadFrames when a frame is missing or unreadable.
MotionMaps CollectMotionMaps(const std::vector<ClipInfo>& clips, int frames, int windows,
                             const std::function<void(int, int)>& progress = {});

// A motion map slid by dx cells to the right and dy cells down (negative: left, up), as the map
// of a crop that does not centre the flag: what slides in is still (0), what slides out is lost,
// and the result is scaled to average 1 again (MotionMap's normalisation; a map left all zeros
// stays zeros).
// Inputs: map  a kMotionMapGrid² CV_32FC1 motion map; |dx|, |dy| < kMotionMapGrid.
// Throws std::invalid_argument for another map or a shift of the whole grid.
cv::Mat ShiftMotionMap(const cv::Mat& map, int dx, int dy);

// Each map of `maps` slid by `distance` cells in each of the 8 directions (dx, dy in
// {-distance, 0, distance}, not both 0; rows of dy, then dx, ascending): 8 maps per map, with
// its wind speed. Throws std::invalid_argument unless 1 <= distance < kMotionMapGrid and every
// map has its wind speed.
MotionMaps ShiftedMotionMaps(const MotionMaps& maps, int distance);

struct FlyJudgeTrainOptions {
  int hidden = 64;             // hidden units
  // Each training map slid by a random dx, dy in -shift..shift cells (ShiftMotionMap), drawn
  // anew every time it is used (0: the maps as collected). Why: FlagSim's cameras all centre the
  // flag, so a judge trained on its maps alone leaned on where the motion sits; a camera that
  // does not centre the flag turned its verdict.
  int shift = 0;
  int epochs = 100;
  int batch = 128;             // maps per Adam step
  double learning_rate = 1e-3;
  double weight_decay = 1e-4;  // Adam's L2 term
  uint64_t seed = 1;           // initialisation and order
};

// Trains a judge to call every map "right" (loss: softplus(-score), the logistic loss of the
// antisymmetric score), by Adam over shuffled batches.
// Inputs: maps  N >= 1 motion maps of flags that fly right; options; epoch_done  called after
// each epoch with (epoch, epochs, mean loss) (may be empty).
// Throws std::invalid_argument when there are no maps or an option is out of range.
FlyJudge TrainFlyJudge(const std::vector<cv::Mat>& maps, const FlyJudgeTrainOptions& options,
                       const std::function<void(int, int, double)>& epoch_done = {});

// How often a judge is right about maps of flags that fly right, and by the same count (its
// score is antisymmetric) about their mirror images.
struct FlyJudgeAccuracy {
  int count = 0;
  int right = 0;      // score >= the judge's margin (and > 0)
  int undecided = 0;  // |score| < margin, or 0 (a still clip): the judge tells nothing; not counted right
  double accuracy() const { return count > 0 ? static_cast<double>(right) / count : 0.0; }
  // Per 2 m/s band of wind speed [0, 2), [2, 4), ..., the last band open above.
  struct Band {
    double low = 0, high = 0;
    int count = 0, right = 0;
  };
  std::vector<Band> bands;
};

// Inputs: judge; maps (e.g. CollectMotionMaps of a test split); band_width [m/s] > 0; bands >= 1.
FlyJudgeAccuracy MeasureFlyJudge(const FlyJudge& judge, const MotionMaps& maps, double band_width = 2.0,
                                 int bands = 5);

// How a judge was made, for its card (FlyJudge::Save adds its shape and margin): "what", "data"
// (the dataset folder), "train_windows_per_clip", "frames", the options' "epochs", "batch",
// "learning_rate", "weight_decay", "seed" and "shift", and "accuracy" as given (e.g. split name ->
// ToJson(FlyJudgeAccuracy)). Every field is one FlyJudge::Load accepts.
nlohmann::json FlyJudgeTrainingCard(const std::string& data, int windows, int frames,
                                    const FlyJudgeTrainOptions& options, const nlohmann::json& accuracy);

// {"count", "right", "undecided", "accuracy", "bands": [{"low", "high", "count", "accuracy"}]}.
nlohmann::json ToJson(const FlyJudgeAccuracy& accuracy);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FLY_JUDGE_TRAIN_H_
