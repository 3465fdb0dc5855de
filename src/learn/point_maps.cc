#include "learn/point_maps.h"

#include <stdexcept>
#include <string>

#include <torch/nn/functional/upsampling.h>

namespace clothwind::learn {

at::Tensor PixelCentres(int64_t n, const at::TensorOptions& options) {
  return (at::arange(n, options) * 2 + 1) / static_cast<double>(n) - 1;
}

at::Tensor SoftArgmax2d(const at::Tensor& logits) {
  if (logits.dim() != 4) {
    throw std::invalid_argument("SoftArgmax2d: expected logits [N, P, H, W], got " + std::to_string(logits.dim()) +
                                " dimensions");
  }
  const int64_t n = logits.size(0), p = logits.size(1), h = logits.size(2), w = logits.size(3);
  const at::Tensor prob = at::softmax(logits.reshape({n, p, h * w}), 2).reshape({n, p, h, w});
  const at::Tensor x = PixelCentres(w, logits.options()), y = PixelCentres(h, logits.options());
  // The marginals' expectations: Σ_j (Σ_i p_ij) x_j and Σ_i (Σ_j p_ij) y_i.
  const at::Tensor u = (prob.sum(2) * x).sum(2);
  const at::Tensor v = (prob.sum(3) * y).sum(2);
  return at::stack({u, v}, 2);
}

PointMapHeadImpl::PointMapHeadImpl(const std::vector<int>& stage_channels, int points, int features) {
  if (stage_channels.empty() || points < 1 || features < 1) {
    throw std::invalid_argument("PointMapHead: needs at least one stage, one point and one feature");
  }
  laterals_ = register_module("laterals", torch::nn::ModuleList());
  for (int channels : stage_channels) {
    laterals_->push_back(torch::nn::Conv2d(torch::nn::Conv2dOptions(channels, features, 1)));
  }
  smooth_ = register_module(
      "smooth", torch::nn::Conv2d(torch::nn::Conv2dOptions(features, features, 3).padding(1).bias(false)));
  smooth_bn_ = register_module("smooth_bn", torch::nn::BatchNorm2d(features));
  out_ = register_module("out", torch::nn::Conv2d(torch::nn::Conv2dOptions(features, points, 1)));
}

at::Tensor PointMapHeadImpl::Logits(const std::vector<at::Tensor>& stages) {
  if (stages.size() != laterals_->size()) {
    throw std::invalid_argument("PointMapHead: expected " + std::to_string(laterals_->size()) + " stage maps, got " +
                                std::to_string(stages.size()));
  }
  // Top-down: each coarser level is upsampled onto the next finer one and added to its lateral.
  namespace F = torch::nn::functional;
  at::Tensor top;
  for (int s = static_cast<int>(stages.size()) - 1; s >= 0; --s) {
    at::Tensor lateral = laterals_->ptr<torch::nn::Conv2dImpl>(s)->forward(stages[s]);
    if (top.defined()) {
      top = F::interpolate(top, F::InterpolateFuncOptions()
                                    .size(std::vector<int64_t>{lateral.size(2), lateral.size(3)})
                                    .mode(torch::kBilinear)
                                    .align_corners(false));
      lateral = lateral + top;
    }
    top = lateral;
  }
  return out_->forward(at::relu(smooth_bn_->forward(smooth_->forward(top))));
}

at::Tensor PointMapHeadImpl::forward(const std::vector<at::Tensor>& stages) { return SoftArgmax2d(Logits(stages)); }

}  // namespace clothwind::learn
