// The weight average's arithmetic on a small module with BatchNorm (parameters, float buffers,
// an integer buffer), its geometric convergence to fixed weights, the noise it removes from
// weights scattered around a minimum, and its refusals.
#include "learn/weight_average.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>
#include <torch/nn/modules/batchnorm.h>
#include <torch/nn/modules/linear.h>

namespace clothwind::learn {
namespace {

// Linear(3 → 4) then BatchNorm1d(4): weights, biases, running stats and a step count.
struct SmallImpl : torch::nn::Module {
  explicit SmallImpl(int out = 4) {
    linear = register_module("linear", torch::nn::Linear(3, out));
    norm = register_module("norm", torch::nn::BatchNorm1d(out));
  }
  at::Tensor forward(const at::Tensor& x) { return norm(linear(x)); }
  torch::nn::Linear linear{nullptr};
  torch::nn::BatchNorm1d norm{nullptr};
};
TORCH_MODULE(Small);

// Gives every float parameter and buffer of `m` random values and its step count `steps`.
void Randomise(Small& m, int64_t steps) {
  at::NoGradGuard no_grad;
  for (auto& p : m->named_parameters()) p.value().copy_(at::randn(p.value().sizes()));
  m->norm->running_mean.copy_(at::randn({4}));
  m->norm->running_var.copy_(at::rand({4}) + 0.5);
  m->norm->num_batches_tracked.fill_(steps);
}

double MaxDifference(const Small& a, const Small& b) {
  double worst = 0;
  const auto pa = a->named_parameters(), pb = b->named_parameters();
  for (const auto& p : pa) worst = std::max(worst, (p.value() - pb[p.key()]).abs().max().item<double>());
  const auto ba = a->named_buffers(), bb = b->named_buffers();
  for (const auto& x : ba) {
    worst = std::max(worst, (x.value().to(at::kDouble) - bb[x.key()].to(at::kDouble)).abs().max().item<double>());
  }
  return worst;
}

TEST(WeightAverage, BlendMixesFloatsAndCopiesTheStepCount) {
  at::manual_seed(1);
  Small from, to, before;
  Randomise(from, 17);
  Randomise(to, 3);
  CopyWeights(*to, *before);
  EXPECT_EQ(MaxDifference(to, before), 0.0);
  BlendWeights(*from, *to, 0.75);
  const auto f = from->named_parameters(), b = before->named_parameters();
  for (const auto& p : to->named_parameters()) {
    const at::Tensor expected = 0.75 * b[p.key()] + 0.25 * f[p.key()];
    EXPECT_TRUE(at::allclose(p.value(), expected, 1e-6, 1e-7)) << p.key();
  }
  EXPECT_TRUE(at::allclose(to->norm->running_mean,
                           0.75 * before->norm->running_mean + 0.25 * from->norm->running_mean, 1e-6, 1e-7));
  EXPECT_TRUE(at::allclose(to->norm->running_var,
                           0.75 * before->norm->running_var + 0.25 * from->norm->running_var, 1e-6, 1e-7));
  EXPECT_EQ(to->norm->num_batches_tracked.item<int64_t>(), 17);
  // d = 1 keeps the average, d = 0 takes the source.
  Small kept;
  CopyWeights(*to, *kept);
  BlendWeights(*from, *to, 1.0);
  EXPECT_LT(MaxDifference(to, kept), 1e-7);
  BlendWeights(*from, *to, 0.0);
  EXPECT_LT(MaxDifference(to, from), 1e-7);
}

TEST(WeightAverage, ConvergesGeometricallyToFixedWeights) {
  at::manual_seed(2);
  Small target, average;
  Randomise(target, 5);
  Randomise(average, 5);  // the same step count: the largest gap is a float one
  const double start = MaxDifference(target, average);
  const double d = 0.9;
  for (int t = 0; t < 50; ++t) BlendWeights(*target, *average, d);
  // Every entry's gap shrinks by exactly d per step: after 50 steps, d^50 of the start's.
  EXPECT_NEAR(MaxDifference(target, average), start * std::pow(d, 50), 1e-6 * start);
}

TEST(WeightAverage, RemovesNoiseAroundAMinimum) {
  // Weights that scatter around w* with standard deviation σ, as an SGD iterate does: the
  // average's error falls to σ · sqrt((1 − d) / (1 + d)) (a first-order autoregression's), here
  // ~0.05 σ, where the last iterate keeps σ.
  at::manual_seed(3);
  Small centre, iterate, average;
  Randomise(centre, 0);
  const double sigma = 0.3, d = 0.995;
  CopyWeights(*centre, *average);
  double last_error = 0, average_error = 0;
  int counted = 0;
  for (int t = 0; t < 6000; ++t) {
    {
      at::NoGradGuard no_grad;
      const auto c = centre->named_parameters();
      for (auto& p : iterate->named_parameters()) p.value().copy_(c[p.key()] + sigma * at::randn(p.value().sizes()));
    }
    BlendWeights(*iterate, *average, AverageDecayAt(d, t));
    if (t >= 3000) {  // after the average has forgotten its start
      const auto c = centre->named_parameters(), it = iterate->named_parameters(),
                 av = average->named_parameters();
      for (const auto& p : c) {
        last_error += (it[p.key()] - p.value()).square().sum().item<double>();
        average_error += (av[p.key()] - p.value()).square().sum().item<double>();
        counted += p.value().numel();
      }
    }
  }
  const double last_rms = std::sqrt(last_error / counted), average_rms = std::sqrt(average_error / counted);
  EXPECT_NEAR(last_rms, sigma, 0.02 * sigma);
  EXPECT_NEAR(average_rms, sigma * std::sqrt((1 - d) / (1 + d)), 0.3 * sigma * std::sqrt((1 - d) / (1 + d)));
}

TEST(WeightAverage, DecayWarmsUpThenHolds) {
  EXPECT_DOUBLE_EQ(AverageDecayAt(0.999, 0), 0.1);
  EXPECT_DOUBLE_EQ(AverageDecayAt(0.999, 10), 11.0 / 20.0);
  EXPECT_DOUBLE_EQ(AverageDecayAt(0.999, 1000000), 0.999);
  for (int64_t t = 0; t < 20000; t += 37) EXPECT_LE(AverageDecayAt(0.999, t), AverageDecayAt(0.999, t + 1));
}

TEST(WeightAverage, RefusesAnotherArchitectureOrDecay) {
  Small four, five(5);
  try {
    CopyWeights(*four, *five);
    FAIL() << "copied between differently shaped networks";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("\"linear.weight\" is shaped [4, 3]"), std::string::npos) << e.what();
  }
  torch::nn::Linear other(3, 4);
  EXPECT_THROW(CopyWeights(*four, *other), std::runtime_error);  // names differ: "weight" vs "linear.weight"
  try {
    CopyWeights(*other, *four);
    FAIL() << "copied from a network without the average's parameters";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no parameter \"linear.weight\""), std::string::npos) << e.what();
  }
  Small same;
  EXPECT_THROW(BlendWeights(*four, *same, 1.5), std::runtime_error);
  EXPECT_THROW(BlendWeights(*four, *same, -0.1), std::runtime_error);
}

}  // namespace
}  // namespace clothwind::learn
