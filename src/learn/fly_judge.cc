#include "learn/fly_judge.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>
#include <torch/nn/module.h>
#include <torch/nn/modules/linear.h>

#include "common/atomic_file.h"
#include "learn/dataset.h"
#include "learn/model_config.h"
#include "learn/weights_io.h"

namespace clothwind::learn {
namespace {

constexpr int kMapSize = kMotionMapGrid * kMotionMapGrid;

// The weights file's layout: two linear layers, as torch would save them ("hidden.weight", ...).
struct JudgeModule : torch::nn::Module {
  explicit JudgeModule(int hidden_units)
      : hidden(register_module("hidden", torch::nn::Linear(kMapSize, hidden_units))),
        output(register_module("output", torch::nn::Linear(hidden_units, 1))) {}
  torch::nn::Linear hidden{nullptr}, output{nullptr};
};

Eigen::VectorXf Flattened(const cv::Mat& map) {
  if (map.type() != CV_32FC1 || map.rows != kMotionMapGrid || map.cols != kMotionMapGrid) {
    throw std::invalid_argument("FlyJudge: expected a " + std::to_string(kMotionMapGrid) + "x" +
                                std::to_string(kMotionMapGrid) + " CV_32FC1 motion map, got " + std::to_string(map.cols) +
                                "x" + std::to_string(map.rows));
  }
  cv::Mat c = map.isContinuous() ? map : map.clone();
  return Eigen::Map<const Eigen::VectorXf>(c.ptr<float>(), kMapSize);
}

}  // namespace

cv::Mat MotionMap(const std::vector<cv::Mat>& frames) {
  if (frames.size() < 2) {
    throw std::invalid_argument("MotionMap: expected at least 2 frames, got " + std::to_string(frames.size()));
  }
  const cv::Size size = frames[0].size();
  const cv::Size side(kMotionMapSide, kMotionMapSide);
  std::vector<cv::Mat> planes(frames.size());
  cv::Mat resized;
  for (size_t t = 0; t < frames.size(); ++t) {
    const cv::Mat& f = frames[t];
    if ((f.type() != CV_8UC1 && f.type() != CV_32FC1) || f.size() != size || f.empty()) {
      throw std::invalid_argument("MotionMap: frame " + std::to_string(t) + " is " + std::to_string(f.cols) + "x" +
                                  std::to_string(f.rows) + " with " + std::to_string(f.channels()) +
                                  " channel(s); expected a non-empty single-channel CV_8UC1 or CV_32FC1 image of " +
                                  std::to_string(size.width) + "x" + std::to_string(size.height) + ", as frame 0");
    }
    if (f.size() == side) {
      resized = f;
    } else {
      cv::resize(f, resized, side, 0, 0, f.cols > kMotionMapSide ? cv::INTER_AREA : cv::INTER_LINEAR);
    }
    resized.convertTo(planes[t], CV_64F);
  }
  cv::Mat grid;
  cv::resize(TemporalStd(planes), grid, cv::Size(kMotionMapGrid, kMotionMapGrid), 0, 0, cv::INTER_AREA);
  const double average = cv::mean(grid)[0];
  cv::Mat map;
  // A still clip (or one whose only change is 8-bit noise far below a grey level) has no shape.
  grid.convertTo(map, CV_32F, average > 1e-6 ? 1.0 / average : 0.0);
  return map;
}

FlyJudge::FlyJudge(Eigen::MatrixXf hidden_weights, Eigen::VectorXf hidden_bias, Eigen::VectorXf output_weights,
                   float output_bias)
    : hidden_weights_(std::move(hidden_weights)),
      hidden_bias_(std::move(hidden_bias)),
      output_weights_(std::move(output_weights)),
      output_bias_(output_bias) {
  const auto h = hidden_bias_.size();
  if (h < 1 || hidden_weights_.rows() != h || hidden_weights_.cols() != kMapSize || output_weights_.size() != h) {
    throw std::invalid_argument("FlyJudge: hidden weights " + std::to_string(hidden_weights_.rows()) + "x" +
                                std::to_string(hidden_weights_.cols()) + ", hidden bias " + std::to_string(h) +
                                ", output weights " + std::to_string(output_weights_.size()) + "; expected Hx" +
                                std::to_string(kMapSize) + ", H, H with H >= 1");
  }
}

namespace {

// Throws naming the card unless it is the one saved inside the weights (`stored`, its JSON; empty
// for a judge saved before the card was stored there: nothing to compare), but for the margin,
// which a user may set on the card. Why: a train-fly-judge stopped between the pair's two renames
// left new weights beside the old card, and the judge ran with the other judge's margin, silently.
void CheckCardMatchesWeights(const nlohmann::json& card, const std::filesystem::path& card_path,
                             const std::string& stored, const std::filesystem::path& weights) {
  if (stored.empty()) return;
  nlohmann::json saved = nlohmann::json::parse(stored, nullptr, /*allow_exceptions=*/false);
  if (!saved.is_object())
    throw std::runtime_error(weights.string() + ": the card stored in the weights is not a JSON object");
  nlohmann::json given = card;
  for (const char* key : {"margin", "margin_note"}) {
    saved.erase(key);
    given.erase(key);
  }
  if (given == saved) return;
  std::string field;
  for (auto it = saved.begin(); it != saved.end() && field.empty(); ++it)
    if (!given.contains(it.key()) || given[it.key()] != it.value()) field = it.key();
  for (auto it = given.begin(); it != given.end() && field.empty(); ++it)
    if (!saved.contains(it.key())) field = it.key();
  throw std::runtime_error(card_path.string() + ": field \"" + field + "\" is " +
                           (given.contains(field) ? given[field].dump() : "missing") + ", but " + weights.string() +
                           " was saved with " + (saved.contains(field) ? saved[field].dump() : "none") +
                           ": not the card written with these weights (a train-fly-judge stopped while it replaced "
                           "them leaves such a pair: train the judge again)");
}

}  // namespace

FlyJudge FlyJudge::Load(const std::filesystem::path& path) {
  RequireWeightsFile(path, "a fly judge");
  const std::filesystem::path card_path = ConfigPathFor(path);
  const nlohmann::json card = ReadJson(card_path);
  // Bounded as train-fly-judge bounds it: the module is built from the card before the weights'
  // shapes are checked, and a card saying 1e9 units asked for a terabyte.
  if (!card.contains("hidden") || !card["hidden"].is_number_integer() || card["hidden"].get<int64_t>() < 1 ||
      card["hidden"].get<int64_t>() > 4096) {
    throw std::runtime_error(card_path.string() +
                             ": field \"hidden\" must be the judge's hidden units (an integer in 1..4096)");
  }
  // A misspelt key ("margn": 1e9) ran the judge at margin 0 without a word: the card holds the
  // fields Load reads and those train-fly-judge writes to say how it was made, nothing else.
  static const char* const kCardFields[] = {"hidden", "grid", "side", "margin", "margin_note", "what", "data",
                                            "train_windows_per_clip", "frames", "epochs", "batch",
                                            "learning_rate", "weight_decay", "seed", "shift", "accuracy"};
  if (card.is_object()) {
    for (auto it = card.begin(); it != card.end(); ++it) {
      if (std::find(std::begin(kCardFields), std::end(kCardFields), it.key()) == std::end(kCardFields))
        throw std::runtime_error(card_path.string() + ": unknown field \"" + it.key() +
                                 "\" (a judge's card holds hidden, grid, side, margin and how it was trained)");
    }
  }
  const auto is_int = [&card](const char* key, int expected) {
    return card.contains(key) && card[key].is_number_integer() && card[key].get<int64_t>() == expected;
  };
  if (!is_int("grid", kMotionMapGrid) || !is_int("side", kMotionMapSide)) {
    throw std::runtime_error(card_path.string() + ": fields \"grid\" and \"side\" must be " +
                             std::to_string(kMotionMapGrid) + " and " + std::to_string(kMotionMapSide) +
                             " (the motion map this build computes)");
  }
  double margin = 0;
  if (card.contains("margin")) {
    if (!card["margin"].is_number() || !std::isfinite(card["margin"].get<double>()) || card["margin"].get<double>() < 0)
      throw std::runtime_error(card_path.string() + ": field \"margin\" must be a finite score >= 0, got " +
                               card["margin"].dump());
    margin = card["margin"].get<double>();
  }
  const int h = card["hidden"].get<int>();
  JudgeModule module(h);
  std::string stored;
  LoadModuleWeights(module, path, &stored);
  CheckCardMatchesWeights(card, card_path, stored, path);
  const at::Tensor w1 = module.hidden->weight.detach().contiguous();
  const at::Tensor b1 = module.hidden->bias.detach().contiguous();
  const at::Tensor w2 = module.output->weight.detach().contiguous();
  // torch is row-major: the H x G*G weight maps onto a row-major Eigen matrix, copied to ours.
  Eigen::MatrixXf hidden_weights =
      Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(w1.data_ptr<float>(), h,
                                                                                               kMapSize);
  FlyJudge judge(std::move(hidden_weights), Eigen::Map<const Eigen::VectorXf>(b1.data_ptr<float>(), h),
                 Eigen::Map<const Eigen::VectorXf>(w2.data_ptr<float>(), h),
                 module.output->bias.detach().item<float>());
  judge.set_margin(margin);
  return judge;
}

void FlyJudge::set_margin(double margin) {
  if (!(std::isfinite(margin) && margin >= 0))
    throw std::invalid_argument("FlyJudge: margin must be a finite score >= 0, got " + std::to_string(margin));
  margin_ = margin;
}

void FlyJudge::Save(const std::filesystem::path& path, nlohmann::json card) const {
  const int h = hidden();
  JudgeModule module(h);
  {
    torch::NoGradGuard no_grad;
    Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> w1 = hidden_weights_;
    module.hidden->weight.copy_(torch::from_blob(w1.data(), {h, kMapSize}, torch::kFloat));
    Eigen::VectorXf b1 = hidden_bias_, w2 = output_weights_;
    module.hidden->bias.copy_(torch::from_blob(b1.data(), {h}, torch::kFloat));
    module.output->weight.copy_(torch::from_blob(w2.data(), {1, h}, torch::kFloat));
    module.output->bias.fill_(output_bias_);
  }
  card["hidden"] = h;
  card["grid"] = kMotionMapGrid;
  card["side"] = kMotionMapSide;
  card["margin"] = margin_;
  // The weights and their card as a pair (WriteFilePairAtomically), as a model's; the card also
  // inside the weights, as a model's configuration (CheckCardMatchesWeights).
  clothwind::WriteFilePairAtomically(path.string(), SerializeModuleWeights(module, WeightPrecision::kFloat32, card.dump()),
                                     ConfigPathFor(path).string(), card.dump(2) + "\n");
}

double FlyJudge::Logit(const Eigen::VectorXf& map) const {
  const Eigen::VectorXf a = (hidden_weights_ * map + hidden_bias_).cwiseMax(0.0f);
  return static_cast<double>(output_weights_.dot(a)) + output_bias_;
}

double FlyJudge::Score(const cv::Mat& map) const {
  cv::Mat mirrored;
  cv::flip(map, mirrored, 1);
  return Logit(Flattened(map)) - Logit(Flattened(mirrored));
}

std::optional<FlyDirection> FlyJudge::Judge(const std::vector<cv::Mat>& frames, double* score) const {
  const double s = Score(MotionMap(frames));
  if (score != nullptr) *score = s;
  return Decide(s);
}

std::optional<FlyDirection> FlyJudge::Decide(double score) const {
  // Inside the margin, a still clip's exact 0, or a score that is not a number (damaged weights):
  // nothing told.
  if (!(std::abs(score) >= margin_) || score == 0) return std::nullopt;
  return score < 0 ? FlyDirection::kLeft : FlyDirection::kRight;
}

}  // namespace clothwind::learn
