// An exponential moving average of a network's weights (Polyak averaging, as timm's ModelEmaV2):
// the mean of the weights the optimiser visited over its last ~1 / (1 − decay) steps. Where
// gradient noise keeps the iterate bouncing around a minimum, the mean sits nearer it than any
// one step, at no cost in training. Torch's module interface only; no training policy.
#ifndef CLOTHWIND_LEARN_WEIGHT_AVERAGE_H_
#define CLOTHWIND_LEARN_WEIGHT_AVERAGE_H_

#include <cstdint>

#include <torch/nn/module.h>

namespace clothwind::learn {

// Copies every parameter and buffer of `from` into the one of the same name in `to`, on to's
// device. Inputs: two modules of one architecture (same names and shapes). Throws
// std::runtime_error naming the first parameter or buffer that `from` lacks or shapes otherwise.
void CopyWeights(const torch::nn::Module& from, torch::nn::Module& to);

// One averaging step: to ← d · to + (1 − d) · from for every floating-point parameter and buffer
// (BatchNorm's running mean and variance are averaged as the weights they normalise for); other
// buffers (BatchNorm's integer step count) are copied. Inputs: modules as CopyWeights; d in [0, 1].
// Throws std::runtime_error as CopyWeights, and for d outside [0, 1].
void BlendWeights(const torch::nn::Module& from, torch::nn::Module& to, double d);

// The decay of averaging step `t` (0-based): min(decay, (1 + t) / (10 + t)) (TensorFlow's and
// timm's warm-up). Early steps, taken from random initial weights, would otherwise linger in the
// mean for ~1 / (1 − decay) steps. With the warm-up the mean spans about the last t / 9 steps
// until the cap binds, from t = 9 / (1 − decay) − 10 on (8990 steps for 0.999).
// Inputs: decay in [0, 1); t >= 0.
double AverageDecayAt(double decay, int64_t t);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_WEIGHT_AVERAGE_H_
