#include "learn/fly_judge_train.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <stdexcept>

#include <torch/torch.h>

namespace clothwind::learn {
namespace {

constexpr int kMapSize = kMotionMapGrid * kMotionMapGrid;

// The maps as an N x G x G float tensor.
at::Tensor Stack(const std::vector<cv::Mat>& maps) {
  at::Tensor x = at::empty({static_cast<int64_t>(maps.size()), kMotionMapGrid, kMotionMapGrid}, at::kFloat);
  for (size_t i = 0; i < maps.size(); ++i) {
    const cv::Mat& m = maps[i];
    if (m.type() != CV_32FC1 || m.rows != kMotionMapGrid || m.cols != kMotionMapGrid) {
      throw std::invalid_argument("TrainFlyJudge: map " + std::to_string(i) + " is not a " +
                                  std::to_string(kMotionMapGrid) + "x" + std::to_string(kMotionMapGrid) +
                                  " CV_32FC1 motion map");
    }
    const cv::Mat c = m.isContinuous() ? m : m.clone();
    std::copy_n(c.ptr<float>(), kMapSize, x[i].data_ptr<float>());
  }
  return x;
}

// Each map of the batch [B, G, G] slid by its own random offset in -shift..shift cells along
// each axis, zeros sliding in, then scaled to average 1 (all-zero maps stay 0).
at::Tensor RandomlyShifted(const at::Tensor& batch, int shift) {
  const int64_t b = batch.size(0), g = kMotionMapGrid;
  const at::Tensor padded = at::constant_pad_nd(batch, {shift, shift, shift, shift}, 0.0);
  const at::Tensor ox = at::randint(0, 2 * shift + 1, {b, 1}, at::kLong);
  const at::Tensor oy = at::randint(0, 2 * shift + 1, {b, 1}, at::kLong);
  const at::Tensor steps = at::arange(g, at::kLong).unsqueeze(0);
  const at::Tensor rows = (oy + steps).reshape({b, g, 1}), cols = (ox + steps).reshape({b, 1, g});
  const at::Tensor shifted = padded.index({at::arange(b, at::kLong).reshape({b, 1, 1}), rows, cols});
  const at::Tensor mean = shifted.mean({1, 2}, /*keepdim=*/true);
  return at::where(mean > 0, shifted / mean.clamp_min(1e-30), shifted);
}

}  // namespace

cv::Mat ShiftMotionMap(const cv::Mat& map, int dx, int dy) {
  if (map.type() != CV_32FC1 || map.rows != kMotionMapGrid || map.cols != kMotionMapGrid)
    throw std::invalid_argument("ShiftMotionMap: expected a " + std::to_string(kMotionMapGrid) + "x" +
                                std::to_string(kMotionMapGrid) + " CV_32FC1 motion map");
  if (std::abs(dx) >= kMotionMapGrid || std::abs(dy) >= kMotionMapGrid)
    throw std::invalid_argument("ShiftMotionMap: shift (" + std::to_string(dx) + ", " + std::to_string(dy) +
                                ") slides the whole map out (|dx|, |dy| < " + std::to_string(kMotionMapGrid) +
                                " expected)");
  cv::Mat out = cv::Mat::zeros(map.size(), CV_32FC1);
  const int w = kMotionMapGrid - std::abs(dx), h = kMotionMapGrid - std::abs(dy);
  map(cv::Rect(std::max(0, -dx), std::max(0, -dy), w, h)).copyTo(out(cv::Rect(std::max(0, dx), std::max(0, dy), w, h)));
  const double mean = cv::mean(out)[0];
  if (mean > 0) out /= mean;
  return out;
}

MotionMaps ShiftedMotionMaps(const MotionMaps& maps, int distance) {
  if (distance < 1 || distance >= kMotionMapGrid || maps.maps.size() != maps.wind_speeds.size())
    throw std::invalid_argument("ShiftedMotionMaps: distance " + std::to_string(distance) + " (1.." +
                                std::to_string(kMotionMapGrid - 1) + " expected) or " +
                                std::to_string(maps.maps.size()) + " maps with " +
                                std::to_string(maps.wind_speeds.size()) + " wind speeds");
  MotionMaps out;
  for (size_t i = 0; i < maps.maps.size(); ++i) {
    for (int dy = -distance; dy <= distance; dy += distance) {
      for (int dx = -distance; dx <= distance; dx += distance) {
        if (dx == 0 && dy == 0) continue;
        out.maps.push_back(ShiftMotionMap(maps.maps[i], dx, dy));
        out.wind_speeds.push_back(maps.wind_speeds[i]);
      }
    }
  }
  return out;
}

MotionMaps CollectMotionMaps(const std::vector<ClipInfo>& clips, int frames, int windows,
                             const std::function<void(int, int)>& progress) {
  MotionMaps out;
  std::vector<cv::Mat> window(frames);
  // Every clip checked before any is read: a short one failed midway, naming no clip or file.
  for (const ClipInfo& clip : clips)
    if (clip.num_frames < frames)
      throw std::runtime_error((clip.dir / "label.json").string() + ": field \"num_frames\" is " +
                               std::to_string(clip.num_frames) + ", the fly judge reads windows of " +
                               std::to_string(frames) + " frames");
  for (size_t i = 0; i < clips.size(); ++i) {
    const ClipInfo& clip = clips[i];
    const std::vector<int> starts = EvenWindowStarts(clip.num_frames, frames, windows);
    const int first = starts.front();
    const std::vector<cv::Mat> all = LoadFrames(clip, first, starts.back() + frames - first);
    const cv::Rect crop = CentreSquare(clip.width, clip.height);
    for (const int start : starts) {
      for (int t = 0; t < frames; ++t) ResizeCrop(all[start - first + t], crop, kMotionMapSide, window[t]);
      out.maps.push_back(MotionMap(window));
      out.wind_speeds.push_back(clip.wind_speed);
    }
    if (progress) progress(static_cast<int>(i + 1), static_cast<int>(clips.size()));
  }
  return out;
}

FlyJudge TrainFlyJudge(const std::vector<cv::Mat>& maps, const FlyJudgeTrainOptions& o,
                       const std::function<void(int, int, double)>& epoch_done) {
  if (maps.empty()) throw std::invalid_argument("TrainFlyJudge: no maps to train on");
  if (o.hidden < 1 || o.epochs < 1 || o.batch < 1 || !(o.learning_rate > 0) || !(o.weight_decay >= 0) ||
      o.shift < 0 || o.shift >= kMotionMapGrid) {
    throw std::invalid_argument("TrainFlyJudge: hidden, epochs and batch must be >= 1, the learning rate > 0, "
                                "the weight decay >= 0 and the shift in 0.." + std::to_string(kMotionMapGrid - 1) +
                                " cells");
  }
  at::manual_seed(o.seed);
  torch::nn::Linear hidden(kMapSize, o.hidden), output(o.hidden, 1);
  const auto logit = [&](const at::Tensor& x) {
    return output->forward(torch::relu(hidden->forward(x.reshape({x.size(0), kMapSize})))).squeeze(1);
  };
  std::vector<at::Tensor> parameters = hidden->parameters();
  for (const at::Tensor& p : output->parameters()) parameters.push_back(p);
  torch::optim::Adam optimizer(parameters,
                               torch::optim::AdamOptions(o.learning_rate).weight_decay(o.weight_decay));
  const at::Tensor x = Stack(maps);
  std::vector<int64_t> order(maps.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(o.seed);
  for (int epoch = 1; epoch <= o.epochs; ++epoch) {
    std::shuffle(order.begin(), order.end(), rng);
    double loss_sum = 0;
    for (size_t i = 0; i < order.size(); i += o.batch) {
      const size_t end = std::min(order.size(), i + o.batch);
      const at::Tensor index = at::tensor(std::vector<int64_t>(order.begin() + i, order.begin() + end), at::kLong);
      at::Tensor batch = x.index_select(0, index);
      if (o.shift > 0) batch = RandomlyShifted(batch, o.shift);
      // Each map against its mirror image (columns reversed): the antisymmetric score.
      const at::Tensor score = logit(batch) - logit(batch.flip({2}));
      const at::Tensor loss = torch::softplus(-score).mean();
      optimizer.zero_grad();
      loss.backward();
      optimizer.step();
      loss_sum += loss.item<double>() * static_cast<double>(end - i);
    }
    if (epoch_done) epoch_done(epoch, o.epochs, loss_sum / static_cast<double>(order.size()));
  }
  const at::Tensor w1 = hidden->weight.detach().contiguous(), b1 = hidden->bias.detach().contiguous();
  const at::Tensor w2 = output->weight.detach().contiguous();
  return FlyJudge(Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
                      w1.data_ptr<float>(), o.hidden, kMapSize),
                  Eigen::Map<const Eigen::VectorXf>(b1.data_ptr<float>(), o.hidden),
                  Eigen::Map<const Eigen::VectorXf>(w2.data_ptr<float>(), o.hidden),
                  output->bias.detach().item<float>());
}

FlyJudgeAccuracy MeasureFlyJudge(const FlyJudge& judge, const MotionMaps& maps, double band_width, int bands) {
  if (!(band_width > 0) || bands < 1) throw std::invalid_argument("MeasureFlyJudge: band_width > 0, bands >= 1");
  FlyJudgeAccuracy a;
  for (int b = 0; b < bands; ++b) a.bands.push_back({b * band_width, (b + 1) * band_width, 0, 0});
  for (size_t i = 0; i < maps.maps.size(); ++i) {
    const double score = judge.Score(maps.maps[i]);
    const std::optional<FlyDirection> way = judge.Decide(score);
    const bool undecided = !way;
    const bool right = way == FlyDirection::kRight;
    ++a.count;
    a.right += right;
    a.undecided += undecided;
    const int b = std::clamp(static_cast<int>(maps.wind_speeds[i] / band_width), 0, bands - 1);
    ++a.bands[b].count;
    a.bands[b].right += right;
  }
  return a;
}

nlohmann::json FlyJudgeTrainingCard(const std::string& data, int windows, int frames,
                                    const FlyJudgeTrainOptions& o, const nlohmann::json& accuracy) {
  return {{"what", "clothwind fly-direction judge (learn/fly_judge.h): which way a flag flies, for models trained "
                   "with --no-flip"},
          {"data", data},
          {"train_windows_per_clip", windows},
          {"frames", frames},
          {"epochs", o.epochs},
          {"batch", o.batch},
          {"learning_rate", o.learning_rate},
          {"weight_decay", o.weight_decay},
          {"seed", o.seed},
          {"shift", o.shift},
          {"accuracy", accuracy}};
}

nlohmann::json ToJson(const FlyJudgeAccuracy& a) {
  nlohmann::json bands = nlohmann::json::array();
  for (const auto& b : a.bands) {
    bands.push_back({{"low", b.low},
                     {"high", b.high},
                     {"count", b.count},
                     {"accuracy", b.count > 0 ? static_cast<double>(b.right) / b.count : 0.0}});
  }
  return {{"count", a.count}, {"right", a.right}, {"undecided", a.undecided}, {"accuracy", a.accuracy()},
          {"bands", bands}};
}

}  // namespace clothwind::learn
