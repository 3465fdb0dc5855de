// The spectral layer against an independent O(N²) DFT written here, plus its batching and its
// commutation with the spatial augmentations (crop, flip).
#include "learn/spectral_layer.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <tuple>
#include <vector>

#include <ATen/ATen.h>
#include <gtest/gtest.h>

namespace clothwind::learn {
namespace {

constexpr double kFps = 25.0;

struct Bin {
  double power;
  int index;
};

// Periodogram of one signal by the textbook DFT, Hann window w_n = 0.5 - 0.5 cos(2πn/N),
// normalised by Σ w_n²; without the DC bin after removing the signal's mean. length > N: the DFT
// of the windowed signal followed by length - N zeros. local_peaks: only bins no neighbour
// exceeds (left >=, right >) are returned. Sorted by descending power.
std::vector<Bin> NaivePeriodogram(std::vector<double> x, bool include_dc, int length = 0,
                                  bool local_peaks = false) {
  const int n = static_cast<int>(x.size());
  const double mean = std::accumulate(x.begin(), x.end(), 0.0) / n;
  if (!include_dc) {
    for (double& v : x) v -= mean;
  }
  std::vector<double> w(n);
  double w2 = 0;
  for (int i = 0; i < n; ++i) {
    w[i] = 0.5 - 0.5 * std::cos(2 * M_PI * i / n);
    w2 += w[i] * w[i];
  }
  const int l = length == 0 ? n : length;
  std::vector<Bin> bins;
  for (int j = include_dc ? 0 : 1; j <= l / 2; ++j) {
    double re = 0, im = 0;
    for (int i = 0; i < n; ++i) {
      re += w[i] * x[i] * std::cos(2 * M_PI * j * i / l);
      im -= w[i] * x[i] * std::sin(2 * M_PI * j * i / l);
    }
    bins.push_back({(re * re + im * im) / w2, j});
  }
  if (local_peaks) {
    std::vector<Bin> peaks;
    for (size_t i = 0; i < bins.size(); ++i) {
      const bool left_ok = i == 0 || bins[i].power >= bins[i - 1].power;
      const bool right_ok = i + 1 == bins.size() || bins[i].power > bins[i + 1].power;
      if (left_ok && right_ok) peaks.push_back(bins[i]);
    }
    bins = peaks;
  }
  std::stable_sort(bins.begin(), bins.end(), [](const Bin& a, const Bin& b) { return a.power > b.power; });
  return bins;
}

// Pixel signals of a [nb, c, nt, h, w] clip as a double tensor of known content.
at::Tensor RandomClip(int64_t nb, int64_t c, int64_t nt, int64_t h, int64_t w, uint64_t seed) {
  at::manual_seed(seed);
  return at::randn({nb, c, nt, h, w}, at::kDouble);
}

std::vector<double> PixelSignal(const at::Tensor& x, int64_t b, int64_t c, int64_t y, int64_t xx) {
  at::Tensor s = x.index({b, c, at::indexing::Slice(), y, xx}).contiguous().to(at::kDouble);
  return std::vector<double>(s.data_ptr<double>(), s.data_ptr<double>() + s.numel());
}

TEST(SpectralLayer, OscillatingPixelsGiveTheirFrequencyAndPower) {
  // Each pixel oscillates at its own whole-bin frequency on top of a bright mean (DC), so the
  // strongest non-DC bin must be that frequency, in Hz at 25 fps.
  const int64_t nt = 30, h = 3, w = 5;
  at::Tensor x = at::zeros({1, 1, nt, h, w}, at::kDouble);
  std::vector<int> expected_bin(h * w);
  for (int64_t y = 0; y < h; ++y) {
    for (int64_t xx = 0; xx < w; ++xx) {
      const int bin = 1 + static_cast<int>((y * w + xx) % 14);
      expected_bin[y * w + xx] = bin;
      const double amplitude = 0.5 + 0.1 * xx, phase = 0.3 * y;
      for (int64_t t = 0; t < nt; ++t) {
        x.index_put_({0, 0, t, y, xx},
                     100.0 + amplitude * std::cos(2 * M_PI * bin * t / nt + phase));
      }
    }
  }
  SpectralMaps maps = SpectralDecomposition(x, 1, kFps);
  ASSERT_EQ(maps.power.sizes(), (at::IntArrayRef{1, 1, h, w}));
  for (int64_t y = 0; y < h; ++y) {
    for (int64_t xx = 0; xx < w; ++xx) {
      const int bin = expected_bin[y * w + xx];
      EXPECT_NEAR(maps.frequency.index({0, 0, y, xx}).item<double>(), bin * kFps / nt, 1e-9)
          << "pixel " << y << "," << xx;
      // A whole-bin cosine of amplitude A under a Hann window: |X_j| = A/2 · Σw = A N / 4 and
      // Σw² = 3N/8; checked against this closed form and against the naive DFT.
      const double amplitude = 0.5 + 0.1 * xx;
      const double closed_form = std::pow(amplitude * nt / 4.0, 2) / (3.0 * nt / 8.0);
      const auto naive = NaivePeriodogram(PixelSignal(x, 0, 0, y, xx), false);
      EXPECT_EQ(naive[0].index, bin);
      EXPECT_NEAR(maps.power.index({0, 0, y, xx}).item<double>(), naive[0].power, 1e-9 * naive[0].power);
      EXPECT_NEAR(naive[0].power, closed_form, 1e-9 * closed_form);
    }
  }
  // The bright mean (100) must not leak into the result: the same clip without it gives the
  // same maps.
  SpectralMaps dark = SpectralDecomposition(x - 100.0, 1, kFps);
  EXPECT_TRUE(at::allclose(dark.power, maps.power, 1e-9, 1e-9));
  EXPECT_TRUE(at::equal(dark.frequency, maps.frequency));
}

TEST(SpectralLayer, WithDcTheMeanBrightnessIsTheStrongestBin) {
  // Algorithm 1 verbatim (include_dc): no detrend, so a pixel's mean m is bin 0 with
  // |X_0| = m Σw = m N/2 and power (m N/2)² / (3N/8) = 2 m² N / 3, frequency 0; pixels of
  // different brightness keep their order. Without DC the same clip is unaffected by m.
  const int64_t nt = 30;
  at::Tensor x = at::zeros({1, 1, nt, 1, 2}, at::kDouble);
  for (int64_t t = 0; t < nt; ++t) {
    const double wave = 0.2 * std::cos(2 * M_PI * 4 * t / nt);
    x.index_put_({0, 0, t, 0, 0}, 3.0 + wave);
    x.index_put_({0, 0, t, 0, 1}, -1.5 + wave);
  }
  SpectralMaps maps = SpectralDecomposition(x, 1, kFps, /*include_dc=*/true);
  EXPECT_NEAR(maps.power.index({0, 0, 0, 0}).item<double>(), 2.0 * 9.0 * nt / 3.0, 1e-9);
  EXPECT_NEAR(maps.power.index({0, 0, 0, 1}).item<double>(), 2.0 * 2.25 * nt / 3.0, 1e-9);
  EXPECT_EQ(maps.frequency.index({0, 0, 0, 0}).item<double>(), 0.0);
  SpectralMaps motion = SpectralDecomposition(x, 1, kFps, /*include_dc=*/false);
  EXPECT_NEAR(motion.frequency.index({0, 0, 0, 0}).item<double>(), 4 * kFps / nt, 1e-12);
  EXPECT_NEAR(motion.power.index({0, 0, 0, 0}).item<double>(),
              motion.power.index({0, 0, 0, 1}).item<double>(), 1e-9);
}

void ExpectMatchesNaive(const at::Tensor& x, int k, bool include_dc) {
  SpectralMaps maps = SpectralDecomposition(x, k, kFps, include_dc);
  const int64_t nb = x.size(0), c = x.size(1), nt = x.size(2), h = x.size(3), w = x.size(4);
  ASSERT_EQ(maps.power.sizes(), (at::IntArrayRef{nb, k * c, h, w}));
  ASSERT_EQ(maps.frequency.sizes(), (at::IntArrayRef{nb, k * c, h, w}));
  for (int64_t b = 0; b < nb; ++b)
    for (int64_t ch = 0; ch < c; ++ch)
      for (int64_t y = 0; y < h; ++y)
        for (int64_t xx = 0; xx < w; ++xx) {
          const auto naive = NaivePeriodogram(PixelSignal(x, b, ch, y, xx), include_dc);
          for (int i = 0; i < k; ++i) {
            const double p = maps.power.index({b, ch * k + i, y, xx}).item<double>();
            const double f = maps.frequency.index({b, ch * k + i, y, xx}).item<double>();
            EXPECT_NEAR(p, naive[i].power, 1e-9 * (1 + naive[i].power))
                << "b" << b << " c" << ch << " y" << y << " x" << xx << " peak " << i;
            EXPECT_NEAR(f, naive[i].index * kFps / nt, 1e-12) << "peak " << i << " nt " << nt;
          }
        }
}

TEST(SpectralLayer, TopKMatchesNaiveDftForRandomSignals) {
  // k and N_t as parameters, even and odd lengths, several channels.
  ExpectMatchesNaive(RandomClip(2, 2, 30, 3, 4, 1), 3, false);
  ExpectMatchesNaive(RandomClip(1, 3, 31, 2, 3, 2), 2, false);
  ExpectMatchesNaive(RandomClip(2, 1, 20, 2, 2, 3), 4, true);
  ExpectMatchesNaive(RandomClip(1, 1, 10, 3, 3, 4), 5, false);  // every candidate bin
}

// A pixel oscillating at `hz` with amplitude `amplitude` (plus `second` at `hz2`), N_t frames.
at::Tensor Oscillation(int nt, double hz, double amplitude, double hz2 = 0, double second = 0) {
  at::Tensor x = at::zeros({1, 1, nt, 1, 1}, at::kDouble);
  for (int n = 0; n < nt; ++n) {
    const double t = n / kFps;
    x.index_put_({0, 0, n, 0, 0}, amplitude * std::sin(2 * M_PI * hz * t + 0.3) +
                                      second * std::sin(2 * M_PI * hz2 * t + 1.1));
  }
  return x;
}

TEST(SpectralLayer, ZeroPaddedDftMatchesNaiveDft) {
  for (const auto& [nt, length, k, peaks] :
       std::vector<std::tuple<int, int, int, bool>>{{30, 120, 3, false}, {31, 64, 2, false},
                                                    {30, 120, 3, true}, {20, 20, 2, true}}) {
    at::Tensor x = RandomClip(2, 1, nt, 2, 3, 10 + nt + length);
    SpectralOptions o;
    o.k = k;
    o.dft_size = length;
    o.local_peaks = peaks;
    SpectralMaps maps = SpectralDecomposition(x, o);
    ASSERT_EQ(maps.power.sizes(), (at::IntArrayRef{2, k, 2, 3}));
    for (int64_t b = 0; b < 2; ++b)
      for (int64_t y = 0; y < 2; ++y)
        for (int64_t xx = 0; xx < 3; ++xx) {
          const auto naive = NaivePeriodogram(PixelSignal(x, b, 0, y, xx), false, length, peaks);
          ASSERT_GE(naive.size(), static_cast<size_t>(k));  // random signals have many peaks
          for (int i = 0; i < k; ++i) {
            EXPECT_NEAR(maps.power.index({b, i, y, xx}).item<double>(), naive[i].power,
                        1e-9 * (1 + naive[i].power)) << "N_t " << nt << " L " << length << " slot " << i;
            EXPECT_NEAR(maps.frequency.index({b, i, y, xx}).item<double>(), naive[i].index * kFps / length, 1e-12)
                << "N_t " << nt << " L " << length << " slot " << i;
          }
        }
  }
}

TEST(SpectralLayer, PaddingResolvesAFrequencyBetweenBins) {
  // 2.9 Hz over 30 frames at 25 fps: the bins are 0.83 Hz apart (2.50, 3.33), so the unpadded
  // layer is 0.4 Hz off; padded to 240 samples (0.10 Hz apart) the peak lands within a bin.
  const double hz = 2.9;
  at::Tensor x = Oscillation(30, hz, 1.0);
  const double coarse = SpectralDecomposition(x, 1, kFps).frequency.item<double>();
  EXPECT_GT(std::abs(coarse - hz), 0.35);
  SpectralOptions o;
  o.k = 1;
  o.dft_size = 240;
  SpectralMaps fine = SpectralDecomposition(x, o);
  EXPECT_NEAR(fine.frequency.item<double>(), hz, kFps / 240);
  // The peak power does not depend on the padding when the tone sits on a bin (1.25 Hz: bin 3
  // unpadded, bin 24 of 240).
  at::Tensor on_bin = Oscillation(60, 1.25, 2.0);
  const double unpadded = SpectralDecomposition(on_bin, 1, kFps).power.item<double>();
  o.dft_size = 480;
  SpectralMaps padded = SpectralDecomposition(on_bin, o);
  EXPECT_NEAR(padded.frequency.item<double>(), 1.25, 1e-12);
  EXPECT_NEAR(padded.power.item<double>(), unpadded, 1e-9 * unpadded);
}

TEST(SpectralLayer, LocalPeaksFindTheSecondToneThatBinsMiss) {
  // Tones at 2.5 Hz (amplitude 1) and 7.5 Hz (0.5) over 60 frames, padded to 240: the three
  // strongest bins all sit on the 2.5 Hz lobe, the two strongest peaks are the two tones, with
  // powers a factor 4 apart (amplitude squared).
  at::Tensor x = Oscillation(60, 2.5, 1.0, 7.5, 0.5);
  SpectralOptions o;
  o.k = 2;
  o.dft_size = 240;
  SpectralMaps bins = SpectralDecomposition(x, o);
  EXPECT_NEAR(bins.frequency.index({0, 1, 0, 0}).item<double>(), 2.5, 0.3);
  o.local_peaks = true;
  SpectralMaps peaks = SpectralDecomposition(x, o);
  EXPECT_NEAR(peaks.frequency.index({0, 0, 0, 0}).item<double>(), 2.5, 1e-12);
  EXPECT_NEAR(peaks.frequency.index({0, 1, 0, 0}).item<double>(), 7.5, 1e-12);
  EXPECT_NEAR(peaks.power.index({0, 0, 0, 0}).item<double>() / peaks.power.index({0, 1, 0, 0}).item<double>(),
              4.0, 0.05);
  // A still pixel has no peak: every slot reads power 0 at 0 Hz.
  SpectralMaps still = SpectralDecomposition(at::ones({1, 1, 60, 1, 1}, at::kDouble), o);
  EXPECT_EQ(still.power.abs().max().item<double>(), 0.0);
  EXPECT_EQ(still.frequency.abs().max().item<double>(), 0.0);
}

// A float clip [n_b, 1, 30, 2, 4]: in example b the left two columns oscillate at 2.5 Hz with
// amplitude amplitude[b] (each pixel its own phase), the right two hold a constant grey
// (0.3 + a pixel's own offset), as a background behind a flag does.
at::Tensor HalfStillClip(const std::vector<double>& amplitude) {
  const int64_t nb = static_cast<int64_t>(amplitude.size());
  at::Tensor x = at::zeros({nb, 1, 30, 2, 4}, at::kFloat);
  auto a = x.accessor<float, 5>();
  for (int64_t b = 0; b < nb; ++b)
    for (int n = 0; n < 30; ++n)
      for (int y = 0; y < 2; ++y)
        for (int xx = 0; xx < 4; ++xx)
          a[b][0][n][y][xx] = xx < 2 ? static_cast<float>(amplitude[b] * std::sin(2 * M_PI * 2.5 * n / kFps + 0.7 * (y * 4 + xx)))
                                     : 0.3f + 0.01f * static_cast<float>(y * 4 + xx);
  return x;
}

TEST(SpectralLayer, AStillFloorLetsStillPixelsReadNoMotionInEitherSelectionPath) {
  // Amplitudes 1e-3 and 1e3 in one batch: each clip's floor is its own.
  const at::Tensor x = HalfStillClip({1e-3, 1e3});
  const at::Tensor still = at::zeros({2, 1, 2, 4}, at::kBool).index_put_({"...", at::indexing::Slice(2, 4)}, true)
                               .repeat({1, 3, 1, 1});  // [2, 3 peaks, 2, 4]
  for (const bool one_pass : {true, false}) {
    SpectralOptions o;
    o.k = 3;
    o.phase_steps = true;
    o.one_pass = one_pass;
    const SpectralMaps before = SpectralDecomposition(x, o);
    // Without the floor a still pixel's flat spectrum still names frequencies (bins >= 1: > 0 Hz).
    EXPECT_GT(before.frequency.masked_select(still).min().item<double>(), 0.0) << "one_pass " << one_pass;
    o.still_floor = 1e-6;
    const SpectralMaps after = SpectralDecomposition(x, o);
    EXPECT_EQ(after.power.masked_select(still).abs().max().item<double>(), 0.0) << "one_pass " << one_pass;
    EXPECT_EQ(after.frequency.masked_select(still).abs().max().item<double>(), 0.0) << "one_pass " << one_pass;
    // The moving pixels, in the calm clip too, keep their maps: 2.5 Hz strongest, bit for bit.
    const at::Tensor moving = still.logical_not();
    EXPECT_TRUE(at::equal(after.power.masked_select(moving), before.power.masked_select(moving)));
    EXPECT_TRUE(at::equal(after.frequency.masked_select(moving), before.frequency.masked_select(moving)));
    EXPECT_NEAR(after.frequency.index({0, 0, 0, 0}).item<double>(), 2.5, 1e-6);
    EXPECT_NEAR(after.frequency.index({1, 0, 1, 1}).item<double>(), 2.5, 1e-6);
    EXPECT_TRUE(at::equal(after.phase, before.phase));
  }
  // The floor removes stillness, not a camera's noise: one grey level (of 255) of noise on the
  // still half keeps its peaks, as a real camera's background does (docs/sdn.md says so).
  {
    at::manual_seed(11);
    at::Tensor noisy = HalfStillClip({1.0});
    noisy.narrow(4, 2, 2).add_(at::randn({1, 1, 30, 2, 2}) / 255.0);
    SpectralOptions o;
    o.still_floor = 1e-6;
    const SpectralMaps maps = SpectralDecomposition(noisy, o);
    EXPECT_GT(maps.frequency.narrow(3, 2, 2).abs().min().item<double>(), 0.0);
    EXPECT_GT(maps.power.narrow(3, 2, 2).min().item<double>(), 0.0);
  }
  // A clip with nothing moving reads no motion anywhere.
  SpectralOptions o;
  o.still_floor = 1e-6;
  const SpectralMaps calm = SpectralDecomposition(HalfStillClip({0.0}), o);
  EXPECT_EQ(calm.frequency.abs().max().item<double>(), 0.0);
  for (const double bad : {-1e-6, std::nan("")}) {
    o.still_floor = bad;
    EXPECT_THROW(SpectralDecomposition(x, o), std::invalid_argument) << bad;
  }
}

// A wave cos(2π f t − κx x − κy y + φ0) over an h × w image, N_t frames.
at::Tensor TravellingWave(int nt, int h, int w, double hz, double kx, double ky, double phi0) {
  at::Tensor x = at::zeros({1, 1, nt, h, w}, at::kDouble);
  auto a = x.accessor<double, 5>();
  for (int n = 0; n < nt; ++n)
    for (int y = 0; y < h; ++y)
      for (int xx = 0; xx < w; ++xx) a[0][0][n][y][xx] = std::cos(2 * M_PI * hz * n / kFps - kx * xx - ky * y + phi0);
  return x;
}

TEST(SpectralLayer, PhaseStepsReadATravellingWavesWavenumber) {
  // 2.5 Hz is bin 3 of 30 frames, so every pixel's strongest bin is the wave's.
  const double kx = 0.4, ky = -0.25;
  SpectralOptions o;
  o.k = 2;
  o.phase_steps = true;
  SpectralMaps maps = SpectralDecomposition(TravellingWave(30, 4, 5, 2.5, kx, ky, 0.7), o);
  ASSERT_EQ(maps.phase.sizes(), (at::IntArrayRef{1, 4, 4, 5}));
  auto ph = maps.phase.accessor<double, 4>();
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) {
      if (x < 4) {
        EXPECT_NEAR(ph[0][0][y][x], std::cos(kx), 1e-6) << y << "," << x;
        EXPECT_NEAR(ph[0][1][y][x], std::sin(kx), 1e-6) << y << "," << x;
      } else {
        EXPECT_EQ(ph[0][0][y][x], 0.0);  // no right neighbour
        EXPECT_EQ(ph[0][1][y][x], 0.0);
      }
      if (y < 3) {
        EXPECT_NEAR(ph[0][2][y][x], std::cos(ky), 1e-6) << y << "," << x;
        EXPECT_NEAR(ph[0][3][y][x], std::sin(ky), 1e-6) << y << "," << x;
      } else {
        EXPECT_EQ(ph[0][2][y][x], 0.0);
        EXPECT_EQ(ph[0][3][y][x], 0.0);
      }
    }
  // The step does not depend on when the clip began (the wave's phase at t = 0), nor on a padded
  // DFT, but the wave going the other way flips the sine.
  o.dft_size = 120;
  SpectralMaps later = SpectralDecomposition(TravellingWave(30, 4, 5, 2.5, kx, ky, 2.9), o);
  EXPECT_TRUE(at::allclose(later.phase, maps.phase, 1e-6, 1e-6));
  SpectralMaps back = SpectralDecomposition(TravellingWave(30, 4, 5, 2.5, -kx, ky, 0.7), o);
  EXPECT_NEAR(back.phase.index({0, 1, 0, 0}).item<double>(), -std::sin(kx), 1e-6);
  // Still pixels read no step; without the option there is no phase map.
  at::Tensor still = TravellingWave(30, 4, 5, 2.5, kx, ky, 0.7);
  still.narrow(4, 0, 2).zero_();
  SpectralMaps half = SpectralDecomposition(still, o);
  EXPECT_LT(half.phase.narrow(3, 0, 1).abs().max().item<double>(), 1e-3);
  EXPECT_FALSE(SpectralDecomposition(still, 2, kFps).phase.defined());
}

TEST(SpectralLayer, PhaseStepsOfAClipDoNotDependOnItsBatch) {
  // A calm clip (amplitude 1e-3) batched with a violent one (1e3): with ε taken over the batch
  // (1e-6 of the mean |X|², set by the violent clip) the calm clip's steps shrank to ~0; each
  // clip's own ε leaves them at (cos κ, sin κ) as when the calm clip is alone (sdn_node's batch
  // of one). Both selection paths.
  const double kx = 0.4, ky = -0.25;
  const at::Tensor calm = 1e-3 * TravellingWave(30, 4, 5, 2.5, kx, ky, 0.7);
  const at::Tensor violent = 1e3 * TravellingWave(30, 4, 5, 2.5, -kx, ky, 1.3);
  const at::Tensor batch = at::cat({calm, violent}, 0);
  for (const bool one_pass : {true, false}) {
    SCOPED_TRACE(one_pass ? "one pass" : "tensor path");
    SpectralOptions o;
    o.k = 2;
    o.phase_steps = true;
    o.one_pass = one_pass;
    const at::Tensor alone = SpectralDecomposition(calm, o).phase;
    const at::Tensor batched = SpectralDecomposition(batch, o).phase;
    EXPECT_TRUE(at::allclose(batched.narrow(0, 0, 1), alone, 1e-12, 1e-12));
    EXPECT_NEAR(batched.index({0, 0, 0, 0}).item<double>(), std::cos(kx), 1e-4);
    EXPECT_NEAR(batched.index({0, 1, 0, 0}).item<double>(), std::sin(kx), 1e-4);
    EXPECT_NEAR(batched.index({1, 1, 0, 0}).item<double>(), -std::sin(kx), 1e-4);
    EXPECT_TRUE(at::allclose(batched.narrow(0, 1, 1), SpectralDecomposition(violent, o).phase, 1e-12, 1e-12));
  }
}

TEST(SpectralLayer, FarPhaseStepsTurnByTheWavenumberTimesTheDistance) {
  // Over 3 pixels the same wave turns by 3κ: channels 4..7 read (cos 3κx, sin 3κx, cos 3κy,
  // sin 3κy) where the pixel 3 further exists, 0 elsewhere; channels 0..3 are the near steps.
  const double kx = 0.15, ky = -0.1;
  SpectralOptions o;
  o.k = 2;
  o.phase_steps = true;
  o.phase_step_far = 3;
  const at::Tensor wave = TravellingWave(30, 5, 6, 2.5, kx, ky, 0.7);
  SpectralMaps maps = SpectralDecomposition(wave, o);
  ASSERT_EQ(maps.phase.sizes(), (at::IntArrayRef{1, 8, 5, 6}));
  o.phase_step_far = 0;
  EXPECT_TRUE(at::allclose(maps.phase.narrow(1, 0, 4), SpectralDecomposition(wave, o).phase, 1e-12, 1e-12));
  auto ph = maps.phase.accessor<double, 4>();
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x) {
      EXPECT_NEAR(ph[0][4][y][x], x < 3 ? std::cos(3 * kx) : 0.0, 1e-6) << y << "," << x;
      EXPECT_NEAR(ph[0][5][y][x], x < 3 ? std::sin(3 * kx) : 0.0, 1e-6) << y << "," << x;
      EXPECT_NEAR(ph[0][6][y][x], y < 2 ? std::cos(3 * ky) : 0.0, 1e-6) << y << "," << x;
      EXPECT_NEAR(ph[0][7][y][x], y < 2 ? std::sin(3 * ky) : 0.0, 1e-6) << y << "," << x;
    }
  // A distance of 1 repeats the near steps, and far steps need the near ones: both refused.
  o.phase_step_far = 1;
  EXPECT_THROW(SpectralDecomposition(wave, o), std::invalid_argument);
  o.phase_step_far = 3;
  o.phase_steps = false;
  EXPECT_THROW(SpectralDecomposition(wave, o), std::invalid_argument);
}

// A wave of amplitude A(x, y) = 1 + 0.1x + 0.05y (largest at the last pixel) plus an optional
// second tone of frequency hz2 and amplitude a2 on the first row's first two pixels.
at::Tensor ShapedWave(int h, int w, double kx, double ky, double phi0, double hz2 = 0, double a2 = 0) {
  at::Tensor x = TravellingWave(30, h, w, 2.5, kx, ky, phi0);
  auto a = x.accessor<double, 5>();
  for (int n = 0; n < 30; ++n)
    for (int y = 0; y < h; ++y)
      for (int xx = 0; xx < w; ++xx) {
        a[0][0][n][y][xx] *= 1 + 0.1 * xx + 0.05 * y;
        if (y == 0 && xx < 2) a[0][0][n][y][xx] += a2 * std::sin(2 * M_PI * hz2 * n / kFps);
      }
  return x;
}

TEST(SpectralLayer, ModeShapeReadsTheWavesPhaseRampAgainstTheStrongestPixel) {
  // 2.5 Hz is bin 3 of 30 frames: every pixel's DFT there is A(p)·e^{i(φ0 − κ·p)} times one
  // constant, so the map is A(p)/rms(A) · e^{−iκ·(p − p*)} with p* the last pixel (4, 5).
  const int h = 5, w = 6;
  const double kx = 0.4, ky = -0.25;
  SpectralOptions o;
  o.k = 2;
  o.mode_shape = true;
  SpectralMaps maps = SpectralDecomposition(ShapedWave(h, w, kx, ky, 0.7), o);
  ASSERT_EQ(maps.mode.sizes(), (at::IntArrayRef{1, 2, h, w}));
  double sum_a2 = 0;
  for (int y = 0; y < h; ++y)
    for (int xx = 0; xx < w; ++xx) sum_a2 += std::pow(1 + 0.1 * xx + 0.05 * y, 2);
  const double rms = std::sqrt(sum_a2 / (h * w));
  auto m = maps.mode.accessor<double, 4>();
  for (int y = 0; y < h; ++y)
    for (int xx = 0; xx < w; ++xx) {
      const double amplitude = (1 + 0.1 * xx + 0.05 * y) / rms;
      const double angle = -(kx * (xx - (w - 1)) + ky * (y - (h - 1)));
      EXPECT_NEAR(m[0][0][y][xx], amplitude * std::cos(angle), 1e-9) << y << "," << xx;
      EXPECT_NEAR(m[0][1][y][xx], amplitude * std::sin(angle), 1e-9) << y << "," << xx;
    }
  // Not when the clip began, nor a constant brightness, nor a padded DFT (2.5 Hz is on its grid
  // too) changes it; a flip mirrors it.
  EXPECT_TRUE(at::allclose(SpectralDecomposition(ShapedWave(h, w, kx, ky, 2.9), o).mode, maps.mode, 1e-9, 1e-9));
  EXPECT_TRUE(at::allclose(SpectralDecomposition(ShapedWave(h, w, kx, ky, 0.7) + 3.0, o).mode, maps.mode, 1e-9, 1e-9));
  // Undetrended (include_dc) a bright still pixel's mean would be the mode: refused.
  SpectralOptions with_dc = o;
  with_dc.include_dc = true;
  EXPECT_THROW(SpectralDecomposition(ShapedWave(h, w, kx, ky, 0.7), with_dc), std::invalid_argument);
  SpectralOptions padded = o;
  padded.dft_size = 60;
  EXPECT_TRUE(at::allclose(SpectralDecomposition(ShapedWave(h, w, kx, ky, 0.7), padded).mode, maps.mode, 1e-9, 1e-9));
  EXPECT_TRUE(at::allclose(SpectralDecomposition(ShapedWave(h, w, kx, ky, 0.7).flip({4}), o).mode,
                           maps.mode.flip({3}), 1e-12, 1e-12));
  // The wave going the other way along x turns the ramp the other way.
  SpectralMaps back = SpectralDecomposition(ShapedWave(h, w, -kx, ky, 0.7), o);
  EXPECT_NEAR(back.mode.index({0, 1, h - 1, 0}).item<double>(),
              -m[0][1][h - 1][0], 1e-9);
  // Without the option there is no mode map; a still clip reads zeros, not 0/0.
  EXPECT_FALSE(SpectralDecomposition(ShapedWave(h, w, kx, ky, 0.7), 2, kFps).mode.defined());
  SpectralMaps still = SpectralDecomposition(at::full({1, 1, 30, h, w}, 2.0, at::kDouble), o);
  EXPECT_EQ(still.mode.abs().max().item<double>(), 0.0);
}

TEST(SpectralLayer, ModeShapeFollowsTheToneWithTheMostPowerOverTheImage) {
  // A 5 Hz tone (bin 6) on two pixels: weaker over the image than the wave, it leaves the map as
  // it was; four times stronger per pixel than the wave's largest, it carries more power over
  // the image than the wave and the map shows it instead (zero where it is absent).
  const int h = 5, w = 6;
  SpectralOptions o;
  o.k = 2;
  o.mode_shape = true;
  const at::Tensor base = SpectralDecomposition(ShapedWave(h, w, 0.4, -0.25, 0.7), o).mode;
  EXPECT_TRUE(at::allclose(SpectralDecomposition(ShapedWave(h, w, 0.4, -0.25, 0.7, 5.0, 1.0), o).mode, base,
                           1e-9, 1e-9));
  at::Tensor tone = SpectralDecomposition(ShapedWave(h, w, 0.4, -0.25, 0.7, 5.0, 8.0), o).mode;
  // The two tone pixels in phase: both read (√(h·w/2), 0) against each other; all others 0.
  const double expected = std::sqrt(h * w / 2.0);
  EXPECT_NEAR(tone.index({0, 0, 0, 0}).item<double>(), expected, 1e-9);
  EXPECT_NEAR(tone.index({0, 0, 0, 1}).item<double>(), expected, 1e-9);
  EXPECT_LT(tone.narrow(2, 1, h - 1).abs().max().item<double>(), 1e-9);
  // Batched clips are decomposed each on its own.
  at::Tensor both = SpectralDecomposition(
      at::cat({ShapedWave(h, w, 0.4, -0.25, 0.7), ShapedWave(h, w, 0.4, -0.25, 0.7, 5.0, 8.0)}, 0), o).mode;
  EXPECT_TRUE(at::allclose(both.narrow(0, 0, 1), base, 1e-12, 1e-12));
  EXPECT_TRUE(at::allclose(both.narrow(0, 1, 1), tone, 1e-12, 1e-12));
}

TEST(SpectralLayer, FloatInputAgreesWithDouble) {
  at::Tensor x = RandomClip(1, 1, 30, 4, 4, 5);
  SpectralMaps d = SpectralDecomposition(x, 2, kFps);
  SpectralMaps f = SpectralDecomposition(x.to(at::kFloat), 2, kFps);
  EXPECT_EQ(f.power.scalar_type(), at::kFloat);
  EXPECT_TRUE(at::allclose(f.power.to(at::kDouble), d.power, 1e-4, 1e-5));
  EXPECT_TRUE(at::allclose(f.frequency.to(at::kDouble), d.frequency, 1e-6, 1e-6));
}

TEST(SpectralLayer, BatchEqualsPerExample) {
  at::Tensor x = RandomClip(4, 2, 30, 5, 6, 6);
  at::Tensor batched = StackSpectralMaps(SpectralDecomposition(x, 3, kFps));
  ASSERT_EQ(batched.sizes(), (at::IntArrayRef{4, 2 * 3 * 2, 5, 6}));
  for (int64_t b = 0; b < 4; ++b) {
    at::Tensor one = StackSpectralMaps(SpectralDecomposition(x.narrow(0, b, 1), 3, kFps));
    EXPECT_TRUE(at::equal(one, batched.narrow(0, b, 1))) << "example " << b;
  }
}

TEST(SpectralLayer, AClipWithStillPixelsGetsTheSameMapsInAnyBatch) {
  // FlagSim's frames hold many pixels that do not change; normalised per clip, their value is no
  // binary fraction. Their detrended signal is rounding only, and which of its near-zero bins is
  // "strongest" followed the rounding of a mean computed over the whole batch: the same clip read
  // frequencies up to 12.5 Hz apart on thousands of pixels, and its estimate moved by up to
  // 0.1 m/s between sdn_node (one clip), eval (8) and the calibration (16). Float, as inference.
  at::manual_seed(3);
  at::Tensor clip = at::randn({1, 1, 30, 16, 16}, at::kFloat);
  clip.narrow(3, 0, 8).fill_(-0.7312345f);  // the top half still
  const at::Tensor batch = at::cat({clip, at::randn({15, 1, 30, 16, 16}, at::kFloat)}, 0);
  for (const bool one_pass : {true, false}) {
    SCOPED_TRACE(one_pass ? "one pass" : "tensor path");
    SpectralOptions o;
    o.k = 3;
    o.phase_steps = true;
    o.one_pass = one_pass;
    const SpectralMaps alone = SpectralDecomposition(clip, o), batched = SpectralDecomposition(batch, o);
    EXPECT_TRUE(at::equal(batched.frequency.narrow(0, 0, 1), alone.frequency));
    EXPECT_TRUE(at::equal(batched.power.narrow(0, 0, 1), alone.power));
    EXPECT_TRUE(at::equal(batched.phase.narrow(0, 0, 1), alone.phase));
  }
}

TEST(SpectralLayer, CommutesWithCropAndHorizontalFlip) {
  // The layer is per pixel, so caching its output and augmenting afterwards is equivalent to
  // augmenting the clip first, for crops and flips (not for resampling).
  at::Tensor x = RandomClip(2, 1, 30, 8, 9, 7);
  auto layer = [](const at::Tensor& t) { return StackSpectralMaps(SpectralDecomposition(t, 2, kFps)); };
  at::Tensor maps = layer(x);
  EXPECT_TRUE(at::equal(layer(x.flip({4})), maps.flip({3})));
  EXPECT_TRUE(at::equal(layer(x.narrow(3, 2, 5).narrow(4, 1, 6)), maps.narrow(2, 2, 5).narrow(3, 1, 6)));
  // Sanity checks that the comparisons above can fail: the flipped clip's maps are not the
  // unflipped maps, and a temporal shift, not a spatial augmentation, changes them. (Compared
  // with maps.flip({3}), the shift's check held whatever the layer did with time.)
  EXPECT_FALSE(at::equal(layer(x.flip({4})), maps));
  EXPECT_FALSE(at::equal(layer(x.roll({3}, {2})), maps));
}

TEST(SpectralLayer, RejectsBadShapesAndK) {
  EXPECT_THROW(SpectralDecomposition(at::zeros({1, 30, 4, 4}), 1, kFps), std::invalid_argument);
  EXPECT_THROW(SpectralDecomposition(at::zeros({1, 1, 1, 4, 4}), 1, kFps), std::invalid_argument);
  EXPECT_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), 16, kFps), std::invalid_argument);
  EXPECT_NO_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), 15, kFps));
  EXPECT_NO_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), 16, kFps, true));
  EXPECT_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), 0, kFps), std::invalid_argument);
  SpectralOptions short_dft;
  short_dft.k = 1;
  short_dft.dft_size = 20;  // shorter than the 30 frames
  EXPECT_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), short_dft), std::invalid_argument);
  short_dft.dft_size = 120;
  short_dft.k = 60;  // 120 samples offer 60 bins without DC
  EXPECT_NO_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), short_dft));
  short_dft.k = 61;
  EXPECT_THROW(SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}), short_dft), std::invalid_argument);
  // A float16 clip is refused as such (it failed inside libtorch's window with a stack trace).
  try {
    SpectralDecomposition(at::zeros({1, 1, 30, 4, 4}, at::kHalf), 1, kFps);
    ADD_FAILURE() << "a float16 clip was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("expected a float32 or float64 tensor, got Half"), std::string::npos) << e.what();
  }
}

// The power's scale, as spectral_layer.h says it: a cosine of amplitude A at an interior bin reads
// A² N_t / 6 (periodic Hann window, |X|² / Σw²), at Nyquist 4 times that.
TEST(SpectralLayer, PowerOfACosineIsAmplitudeSquaredTimesNtOverSix) {
  const int nt = 30;
  for (const auto& [bin, expected] : {std::pair{5, 2.0 * 2.0 * nt / 6.0}, std::pair{15, 4 * 2.0 * 2.0 * nt / 6.0}}) {
    at::Tensor x = at::zeros({1, 1, nt, 1, 1}, at::kDouble);
    for (int t = 0; t < nt; ++t) x[0][0][t][0][0] = 2.0 * std::cos(2 * M_PI * bin * t / nt);
    const SpectralMaps m = SpectralDecomposition(x, 1, kFps);
    EXPECT_NEAR(m.power.item<double>(), expected, 1e-9 * expected) << "bin " << bin;
    EXPECT_NEAR(m.frequency.item<double>(), bin * kFps / nt, 1e-12);
  }
}

TEST(SpectralLayer, IsDifferentiableWithRespectToTheClip) {
  // No weights, but gradients must flow to earlier layers (the power channels depend on x).
  at::Tensor x = RandomClip(1, 1, 16, 2, 2, 8).requires_grad_(true);
  at::Tensor out = StackSpectralMaps(SpectralDecomposition(x, 2, kFps)).sum();
  out.backward();
  ASSERT_TRUE(x.grad().defined());
  EXPECT_GT(x.grad().abs().sum().item<double>(), 0);
}

}  // namespace
}  // namespace clothwind::learn
