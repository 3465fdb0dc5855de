#include "learn/weight_average.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <ATen/core/grad_mode.h>

namespace clothwind::learn {
namespace {

// Pairs each tensor of `to` (parameters, then buffers) with the one of the same name in `from`
// and calls apply(from_tensor, to_tensor); refuses a missing name or another shape.
template <typename Apply>
void ForEachPair(const torch::nn::Module& from, torch::nn::Module& to, Apply apply) {
  at::NoGradGuard no_grad;
  auto pair = [&](const auto& from_dict, auto to_dict, const char* kind) {
    for (auto& item : to_dict) {
      const at::Tensor* source = from_dict.find(item.key());
      if (source == nullptr) {
        throw std::runtime_error(std::string("weight average: the source network has no ") + kind + " \"" +
                                 item.key() + "\"");
      }
      if (!source->sizes().equals(item.value().sizes())) {
        throw std::runtime_error(std::string("weight average: ") + kind + " \"" + item.key() + "\" is shaped " +
                                 c10::str(source->sizes()) + " in the source network, " +
                                 c10::str(item.value().sizes()) + " in the average");
      }
      apply(source->to(item.value().device()), item.value());
    }
  };
  pair(from.named_parameters(), to.named_parameters(), "parameter");
  pair(from.named_buffers(), to.named_buffers(), "buffer");
}

}  // namespace

void CopyWeights(const torch::nn::Module& from, torch::nn::Module& to) {
  ForEachPair(from, to, [](const at::Tensor& source, at::Tensor target) { target.copy_(source); });
}

void BlendWeights(const torch::nn::Module& from, torch::nn::Module& to, double d) {
  if (!(d >= 0 && d <= 1)) throw std::runtime_error("weight average: decay must lie in [0, 1], got " + std::to_string(d));
  ForEachPair(from, to, [d](const at::Tensor& source, at::Tensor target) {
    if (at::isFloatingType(target.scalar_type())) {
      target.mul_(d).add_(source, 1.0 - d);
    } else {
      target.copy_(source);
    }
  });
}

double AverageDecayAt(double decay, int64_t t) {
  return std::min(decay, (1.0 + static_cast<double>(t)) / (10.0 + static_cast<double>(t)));
}

}  // namespace clothwind::learn
