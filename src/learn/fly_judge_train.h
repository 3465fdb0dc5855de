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
// Returns clips.size() * windows maps, clip by clip: each window's centred square, as a model
// reads it, through MotionMap. Throws as LoadFrames when a frame is missing or unreadable.
MotionMaps CollectMotionMaps(const std::vector<ClipInfo>& clips, int frames, int windows,
                             const std::function<void(int, int)>& progress = {});

struct FlyJudgeTrainOptions {
  int hidden = 64;             // hidden units
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

// {"count", "right", "undecided", "accuracy", "bands": [{"low", "high", "count", "accuracy"}]}.
nlohmann::json ToJson(const FlyJudgeAccuracy& accuracy);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FLY_JUDGE_TRAIN_H_
