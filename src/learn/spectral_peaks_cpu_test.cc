// The spectral layer's one-pass CPU selection against its tensor path (SpectralOptions::one_pass
// false, and the path autograd takes): the same maps bit for bit, on random clips and on clips
// full of equal powers (still and quantised pixels), whose order only the sorting steps decide.
#include "learn/spectral_peaks_cpu.h"

#include <string>
#include <utility>

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "learn/spectral_layer.h"

namespace clothwind::learn {
namespace {

void ExpectEqual(const at::Tensor& a, const at::Tensor& b, const std::string& what) {
  ASSERT_EQ(a.sizes(), b.sizes()) << what;
  EXPECT_TRUE(at::equal(a, b)) << what << ": largest difference " << (a - b).abs().max().item<double>();
}

// The layer on clip x through the one pass, through the tensor ops (one_pass false) and through
// autograd's path (a clip that requires grad, whose maps carry its history): all three the same.
void ExpectSameMaps(const at::Tensor& x, SpectralOptions options, const std::string& what) {
  options.one_pass = true;
  const SpectralMaps fast = SpectralDecomposition(x, options);
  options.one_pass = false;
  const SpectralMaps tensor_ops = SpectralDecomposition(x, options);
  options.one_pass = true;
  const SpectralMaps autograd = SpectralDecomposition(x.clone().requires_grad_(true), options);
  ASSERT_TRUE(autograd.power.requires_grad()) << what << ": autograd's maps lost their history";
  for (const auto& [name, reference] : {std::pair{"tensor ops", tensor_ops}, std::pair{"autograd", autograd}}) {
    ExpectEqual(fast.power, reference.power.detach(), what + ", power against " + name);
    ExpectEqual(fast.frequency, reference.frequency.detach(), what + ", frequency against " + name);
    ASSERT_EQ(fast.phase.defined(), options.phase_steps) << what;
    if (options.phase_steps) ExpectEqual(fast.phase, reference.phase.detach(), what + ", phase against " + name);
  }
}

// A [2, 2, 30, 9, 11] float clip: random, with a still square (every frame the same value, so its
// detrended powers are all exactly 0) and quantised pixels (few levels, so powers repeat).
at::Tensor ClipWithTies(uint64_t seed) {
  at::manual_seed(seed);
  at::Tensor x = at::rand({2, 2, 30, 9, 11});
  x.narrow(3, 0, 4).narrow(4, 0, 4).fill_(0.5);
  x.narrow(3, 5, 4).narrow(4, 6, 5).copy_((x.narrow(3, 5, 4).narrow(4, 6, 5) * 2).round() / 2);
  return x;
}

TEST(SpectralPeaksCpu, GivesTheTensorPathsMapsBitForBit) {
  for (const bool include_dc : {false, true}) {
    for (const int dft_size : {0, 64, 400}) {  // 400: 200 candidates, where topk partially sorts
      for (const int far : {0, 3}) {
        SpectralOptions o;
        o.k = 3;
        o.include_dc = include_dc;
        o.dft_size = dft_size;
        o.phase_steps = true;
        o.phase_step_far = far;
        const std::string what = "include_dc " + std::to_string(include_dc) + ", dft_size " +
                                 std::to_string(dft_size) + ", far " + std::to_string(far);
        ExpectSameMaps(ClipWithTies(1), o, what + ", float");
        ExpectSameMaps(ClipWithTies(2).to(at::kDouble), o, what + ", double");
      }
    }
  }
  SpectralOptions no_phase;
  no_phase.k = 5;
  ExpectSameMaps(ClipWithTies(3), no_phase, "k 5 without phase steps");
}

TEST(SpectralPeaksCpu, StillPixelsReadTheTensorPathsBinsAndZeroPhase) {
  // Every pixel still: all powers tie at 0, so the bins are the sorting steps' choice alone.
  SpectralOptions o;
  o.phase_steps = true;
  at::Tensor still = at::full({1, 1, 30, 3, 4}, 0.25);
  ExpectSameMaps(still, o, "still clip");
  SpectralMaps maps = SpectralDecomposition(still, o);
  EXPECT_EQ(maps.power.abs().max().item<double>(), 0.0);
  EXPECT_EQ(maps.phase.abs().max().item<double>(), 0.0);
}

TEST(SpectralPeaksCpu, RefusesSpectraThatDoNotFitTheShape) {
  at::Tensor spectrum = at::zeros({12, 16}, at::kComplexFloat);
  at::Tensor weight_sum = at::ones({}, at::kFloat);
  EXPECT_NO_THROW(SpectralPeaksCpu(spectrum, weight_sum, 1, 15, 3, 25.0 / 30, 1, 1, 3, 4, {1}, {1e-9}));
  EXPECT_THROW(SpectralPeaksCpu(spectrum, weight_sum, 1, 15, 3, 25.0 / 30, 1, 1, 3, 5, {1}, {1e-9}),
               std::invalid_argument);  // 15 pixels asked of 12 rows
  EXPECT_THROW(SpectralPeaksCpu(spectrum, weight_sum, 1, 16, 3, 25.0 / 30, 1, 1, 3, 4, {1}, {1e-9}),
               std::invalid_argument);  // bins 1..16 of 16
  EXPECT_THROW(SpectralPeaksCpu(spectrum, weight_sum, 1, 15, 16, 25.0 / 30, 1, 1, 3, 4, {1}, {1e-9}),
               std::invalid_argument);  // k above the candidates
  EXPECT_THROW(SpectralPeaksCpu(at::zeros({12, 16}), weight_sum, 1, 15, 3, 25.0 / 30, 1, 1, 3, 4, {1}, {1e-9}),
               std::invalid_argument);  // real, not a spectrum
}

}  // namespace
}  // namespace clothwind::learn
