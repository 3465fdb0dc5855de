// A learned judge of which way a flag flies in a clip: a small network on where the clip moves.
//
// A model trained without horizontal flips (train --no-flip) reads a flag flying left 2.5 m/s
// wrong, and the clip's hand-made motion cues (fly_direction.h) say the way right for only 91 %
// of FlagSim's clips. Where the clip moves says far more: the hoist is held by the pole and the
// fly end sweeps, so the temporal-std map's shape (not only its skew along x) tells the side the
// pole is on. A one-hidden-layer network on a 16x16 map of it, trained on FlagSim's clips, is
// right for ~99.6 % of test clips (docs/sdn.md, "Flags that fly left").
//
// The judge is antisymmetric by construction: its score is f(map) - f(mirrored map), so a
// mirrored clip gets exactly the opposite score and the judge cannot prefer a side. It is
// trained (fly_judge_train.h) on clips that all fly right, which by that symmetry is training on
// their mirror images as flying left too.
#ifndef CLOTHWIND_LEARN_FLY_JUDGE_H_
#define CLOTHWIND_LEARN_FLY_JUDGE_H_

#include <filesystem>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "learn/fly_direction.h"

namespace clothwind::learn {

// Where a clip moves, at a scale that does not depend on the camera's resolution or contrast.
// Inputs:
//   frames  T >= 2 single-channel images (CV_8UC1 or CV_32FC1) of one size, in time order: the
//           square a model reads (any side; each is resized to kMotionMapSide first, as the
//           judge was trained)
// Returns a kMotionMapGrid x kMotionMapGrid CV_32FC1 map: each pixel's temporal standard
// deviation, area-averaged onto the grid and divided by its mean, so that it averages 1 (all
// zeros for a still clip). A mirrored clip gives the mirrored map.
// Throws std::invalid_argument naming the frame and what was expected.
constexpr int kMotionMapGrid = 16;
constexpr int kMotionMapSide = 64;
cv::Mat MotionMap(const std::vector<cv::Mat>& frames);

class FlyJudge {
 public:
  // Inputs (H hidden units, G = kMotionMapGrid, the map read row-major as G*G values):
  //   hidden_weights  H x G*G;  hidden_bias  H;  output_weights  H;  output_bias
  // f(map) = output_weights . relu(hidden_weights map + hidden_bias) + output_bias.
  // Throws std::invalid_argument when the shapes disagree.
  FlyJudge(Eigen::MatrixXf hidden_weights, Eigen::VectorXf hidden_bias, Eigen::VectorXf output_weights,
           float output_bias);

  // Reads a judge written by Save: `path` (the weights, weights_io.h) and the card beside it
  // (ConfigPathFor(path), `path` with extension .json: its "hidden" units, map "grid", and the
  // optional "margin").
  // Throws std::runtime_error naming the file and what is missing or of the wrong shape.
  static FlyJudge Load(const std::filesystem::path& path);
  // Writes the weights (float32) to `path` and `card` plus the shape ("hidden", "grid", "side")
  // and the margin to `path` with extension .json, each atomically (temporary file, then rename).
  void Save(const std::filesystem::path& path, nlohmann::json card = nlohmann::json::object()) const;

  int hidden() const { return static_cast<int>(hidden_bias_.size()); }

  // f(map) - f(mirrored map) for a MotionMap: > 0 says the flag flies right, < 0 left; exactly
  // antisymmetric under mirroring the map.
  double Score(const cv::Mat& map) const;

  // The way a clip's flag flies (Score of its MotionMap), or nothing when |score| < margin(): a
  // calm or featureless clip (camera noise scores ~0.4, a flying flag 5-12) would otherwise be
  // turned round on a coin's throw. `score` (may be null) receives the score. Throws as MotionMap.
  std::optional<FlyDirection> Judge(const std::vector<cv::Mat>& frames, double* score = nullptr) const;
  // What a score tells: nothing inside the margin, at exactly 0 or for NaN (damaged weights);
  // else right for > 0, left for < 0. Judge's rule, for callers that hold scores.
  std::optional<FlyDirection> Decide(double score) const;

  // Scores closer to 0 than this decide nothing (the card's "margin"; 0 when it has none: only a
  // still clip's exact 0).
  double margin() const { return margin_; }
  // Throws std::invalid_argument unless margin is finite and >= 0.
  void set_margin(double margin);

  const Eigen::MatrixXf& hidden_weights() const { return hidden_weights_; }
  const Eigen::VectorXf& hidden_bias() const { return hidden_bias_; }
  const Eigen::VectorXf& output_weights() const { return output_weights_; }
  float output_bias() const { return output_bias_; }

 private:
  double Logit(const Eigen::VectorXf& map) const;

  Eigen::MatrixXf hidden_weights_;
  Eigen::VectorXf hidden_bias_;
  Eigen::VectorXf output_weights_;
  float output_bias_ = 0;
  double margin_ = 0;
};

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_FLY_JUDGE_H_
