#include "learn/spectral_layer.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>
#include <string>

#include <ATen/ATen.h>

#include "learn/spectral_peaks_cpu.h"

namespace clothwind::learn {

namespace {

// ε of the phase steps' normalisation, one per example: 1e-6 of the mean |X|² over all bins of
// its C H W one-sided spectra (rows n·CHW .. (n+1)·CHW - 1 of [N_b C H W, F], complex), so that
// still pixels read ~0. Per example, not per batch: a clip's maps must not depend on the clips
// batched with it (a calm clip's ε was set by a flapping one's power in training and eval, and by
// its own in sdn_node's batches of one).
std::vector<double> PhaseStepEps(const at::Tensor& spectrum, int64_t nb) {
  const at::Tensor mean =
      (at::real(spectrum).square() + at::imag(spectrum).square()).reshape({nb, -1}).mean(1).to(at::kDouble).cpu();
  std::vector<double> eps(nb);
  for (int64_t n = 0; n < nb; ++n) eps[n] = 1e-6 * mean[n].item<double>() + 1e-30;
  return eps;
}

// Phase steps over each of `distances` pixels from the one-sided spectra [N_b C H W, F] (complex)
// and each pixel's strongest bin [N_b C H W, 1] (index into F): [N_b, 4C·#distances, H, W]
// (SpectralMaps::phase), one 4C block per distance in order. The spectrum is split and its
// scale ε found once for all distances.
at::Tensor PhaseSteps(const at::Tensor& spectrum, const at::Tensor& bin, int64_t nb, int64_t c, int64_t h,
                      int64_t w, const std::vector<int64_t>& distances) {
  const int64_t f = spectrum.size(1);
  at::Tensor re = at::real(spectrum).reshape({nb, c, h, w, f});
  at::Tensor im = at::imag(spectrum).reshape({nb, c, h, w, f});
  at::Tensor index = bin.reshape({nb, c, h, w, 1});
  // [N_b, 1, 1, 1, 1] in the spectrum's real type: the same rounding as the one-pass path's.
  const std::vector<double> eps_per_example = PhaseStepEps(spectrum, nb);
  const at::Tensor eps = at::tensor(eps_per_example, at::TensorOptions().dtype(at::kDouble))
                             .to(re.scalar_type())
                             .to(re.device())
                             .reshape({nb, 1, 1, 1, 1});
  // One step along spatial dimension `dim` (2: y, down; 3: x, right): pixel p's bin read at p and
  // at the pixel d further, then their normalised cross product.
  auto step = [&](int64_t dim, int64_t d) {
    const int64_t n = dim == 2 ? h : w;
    if (n <= d) return std::make_pair(at::zeros({nb, c, h, w}, re.options()), at::zeros({nb, c, h, w}, re.options()));
    at::Tensor idx = index.narrow(dim, 0, n - d);
    at::Tensor ar = re.narrow(dim, 0, n - d).gather(4, idx), ai = im.narrow(dim, 0, n - d).gather(4, idx);
    at::Tensor br = re.narrow(dim, d, n - d).gather(4, idx), bi = im.narrow(dim, d, n - d).gather(4, idx);
    at::Tensor norm = at::sqrt((ar.square() + ai.square()) * (br.square() + bi.square())) + eps;
    at::Tensor cos = ((ar * br + ai * bi) / norm).squeeze(4);
    at::Tensor sin = ((ai * br - ar * bi) / norm).squeeze(4);
    // Pad the missing last rows/columns with zeros.
    std::vector<int64_t> pad = dim == 3 ? std::vector<int64_t>{0, d} : std::vector<int64_t>{0, 0, 0, d};
    return std::make_pair(at::constant_pad_nd(cos, pad, 0.0), at::constant_pad_nd(sin, pad, 0.0));
  };
  std::vector<at::Tensor> blocks;
  for (const int64_t d : distances) {
    auto [rc, rs] = step(3, d);
    auto [dc, ds] = step(2, d);
    // [N_b, C, 4, H, W] -> [N_b, 4C, H, W], channel 4c + (0..3).
    blocks.push_back(at::stack({rc, rs, dc, ds}, 2).reshape({nb, 4 * c, h, w}));
  }
  return blocks.size() == 1 ? blocks[0] : at::cat(blocks, 1);
}

// The clip's dominant mode (SpectralMaps::mode) from the one-sided spectra [N_b C H W, F]
// (complex) and the candidate bins' periodogram [N_b C H W, candidates], whose bin 0 is spectrum
// bin `first`: [N_b, 2C, H, W].
at::Tensor ModeShape(const at::Tensor& spectrum, const at::Tensor& periodogram, int64_t first, int64_t nb,
                     int64_t c, int64_t h, int64_t w) {
  const int64_t f = spectrum.size(1), candidates = periodogram.size(1);
  // j*: the bin with the most power over the whole image, per example and channel.
  at::Tensor dominant = periodogram.reshape({nb, c, h * w, candidates}).sum(2).argmax(2) + first;  // [nb, c]
  at::Tensor index = dominant.reshape({nb, c, 1, 1}).expand({nb, c, h * w, 1});
  at::Tensor re = at::real(spectrum).reshape({nb, c, h * w, f}).gather(3, index).squeeze(3);  // [nb, c, hw]
  at::Tensor im = at::imag(spectrum).reshape({nb, c, h * w, f}).gather(3, index).squeeze(3);
  at::Tensor amplitude2 = re.square() + im.square();
  at::Tensor reference = amplitude2.argmax(2, /*keepdim=*/true);  // p*, [nb, c, 1]
  at::Tensor rr = re.gather(2, reference), ri = im.gather(2, reference);
  // |R| · rms, with a floor so a still clip reads zeros instead of 0/0.
  at::Tensor scale = at::sqrt(rr.square() + ri.square()) * at::sqrt(amplitude2.mean(2, /*keepdim=*/true)) + 1e-30;
  at::Tensor real = (re * rr + im * ri) / scale;
  at::Tensor imag = (im * rr - re * ri) / scale;
  // [nb, c, 2, hw] -> [nb, 2c, h, w], channel 2c + (0, 1).
  return at::stack({real, imag}, 2).reshape({nb, 2 * c, h, w});
}

// The periodogram of the candidate bins: |X_j|² / Σ w_n² for j = first..first+candidates-1 of
// the one-sided spectra [N_b C H W, F] (complex); [N_b C H W, candidates].
at::Tensor CandidatePeriodogram(const at::Tensor& spectrum, const at::Tensor& window, int64_t first,
                                int64_t candidates) {
  return ((at::real(spectrum).square() + at::imag(spectrum).square()) / window.square().sum())
      .narrow(1, first, candidates);
}

// SpectralOptions::still_floor: the selected bins of maps.power ([N_b, kC, H, W]) at or below
// each example's floor read power 0 and frequency 0 in maps.power and maps.frequency. The floor
// is still_floor times the example's mean of `periodogram` (CandidatePeriodogram, [N_b C H W,
// candidates]), or the power of the detrend's rounding, (N_t · ε · max|x|)² / Σw² with ε the
// clips' dtype's epsilon, if that is larger: in a clip where nothing moves the rounding is all
// the mean holds, and a relative floor alone kept its noise. x is the clips [N_b, C, N_t, H, W].
void ZeroStillPixels(const at::Tensor& x, const at::Tensor& periodogram, const at::Tensor& window,
                     double still_floor, SpectralMaps& maps) {
  const int64_t nb = x.size(0), nt = x.size(2);
  const at::Tensor mean = periodogram.reshape({nb, -1}).mean(1).to(at::kDouble);
  const double epsilon = x.scalar_type() == at::kDouble ? std::numeric_limits<double>::epsilon()
                                                         : std::numeric_limits<float>::epsilon();
  // In the periodogram's units (|X|² / Σw²), as the powers it is compared with.
  const at::Tensor rounding = (x.detach().abs().reshape({nb, -1}).amax(1).to(at::kDouble) * (nt * epsilon)).square() /
                              window.square().sum().to(at::kDouble);
  const at::Tensor floor = at::maximum(still_floor * mean, rounding).reshape({nb, 1, 1, 1}).to(maps.power.scalar_type());
  const at::Tensor still = maps.power.le(floor);
  maps.power = maps.power.masked_fill(still, 0.0);
  maps.frequency = maps.frequency.masked_fill(still, 0.0);
}

}  // namespace

SpectralMaps SpectralDecomposition(const at::Tensor& x, int k, double frame_rate, bool include_dc) {
  SpectralOptions options;
  options.k = k;
  options.frame_rate = frame_rate;
  options.include_dc = include_dc;
  return SpectralDecomposition(x, options);
}

SpectralMaps SpectralDecomposition(const at::Tensor& x, const SpectralOptions& options) {
  const int k = options.k;
  const double frame_rate = options.frame_rate;
  const bool include_dc = options.include_dc;
  if (x.dim() != 5) {
    throw std::invalid_argument("SpectralDecomposition: expected a [N_b, C, N_t, H, W] tensor, got " +
                                std::to_string(x.dim()) + " dimensions");
  }
  // Float32 or float64: libtorch's CPU window and DFT have no float16 kernels, and a half tensor
  // failed deep inside them ("cos_vml_cpu not implemented for 'Half'", with a stack trace).
  if (x.scalar_type() != at::kFloat && x.scalar_type() != at::kDouble)
    throw std::invalid_argument(std::string("SpectralDecomposition: expected a float32 or float64 tensor, got ") +
                                c10::toString(x.scalar_type()));
  const int64_t nb = x.size(0), c = x.size(1), nt = x.size(2), h = x.size(3), w = x.size(4);
  if (nt < 2) throw std::invalid_argument("SpectralDecomposition: N_t must be at least 2");
  if (options.dft_size != 0 && options.dft_size < nt) {
    throw std::invalid_argument("SpectralDecomposition: dft_size = " + std::to_string(options.dft_size) +
                                " is shorter than the clip's N_t = " + std::to_string(nt) +
                                " (0 or at least N_t expected)");
  }
  const int64_t length = options.dft_size == 0 ? nt : options.dft_size;
  const int64_t first = include_dc ? 0 : 1;
  const int64_t candidates = length / 2 + 1 - first;
  if (k < 1 || k > candidates) {
    throw std::invalid_argument("SpectralDecomposition: k = " + std::to_string(k) + " but N_t = " +
                                std::to_string(nt) + " (DFT length " + std::to_string(length) + ") offers " +
                                std::to_string(candidates) + " frequency bins");
  }
  if (!(frame_rate > 0)) throw std::invalid_argument("SpectralDecomposition: frame_rate must be > 0");
  if (options.phase_step_far < 0 || options.phase_step_far == 1 || (options.phase_step_far > 1 && !options.phase_steps)) {
    throw std::invalid_argument("SpectralDecomposition: phase_step_far = " + std::to_string(options.phase_step_far) +
                                " (0, or a distance of at least 2 pixels with phase_steps, expected)");
  }
  if (!(options.still_floor >= 0) || !std::isfinite(options.still_floor)) {
    throw std::invalid_argument("SpectralDecomposition: still_floor = " + std::to_string(options.still_floor) +
                                " (a finite value >= 0 expected)");
  }
  if (options.mode_shape && include_dc) {
    // Undetrended, a pixel's mean brightness leaks through the Hann window into bin 1 and the
    // still image would be the "dominant mode".
    throw std::invalid_argument("SpectralDecomposition: mode_shape needs the detrended spectrum (include_dc off)");
  }
  // [N_b C H W, N_t]: one row per pixel signal.
  // Contiguous whatever the batch: for one clip of one channel the reshape is a transposed view
  // (its rows the pixels, 1 apart), whose mean is reduced across rows in another order than a
  // batch's copied rows. A still pixel's detrended signal is that rounding only, and its
  // "strongest" bin followed it: the same clip read other frequencies on thousands of pixels, and
  // its estimate moved by up to 0.1 m/s between sdn_node (one clip) and eval or the calibration.
  at::Tensor signals = x.permute({0, 1, 3, 4, 2}).reshape({-1, nt}).contiguous();
  at::Tensor window = at::hann_window(nt, /*periodic=*/true, x.options());
  // Without the DC bin the pixel's mean is removed first (else it leaks through the Hann window
  // into bin 1); with it, the signal is taken as it is (Algorithm 1 verbatim), so the DC bin
  // carries the pixel's windowed mean brightness.
  if (!include_dc) signals = signals - signals.mean(1, /*keepdim=*/true);
  at::Tensor spectrum = at::fft_rfft(signals * window, length, /*dim=*/1);
  std::vector<int64_t> distances;
  if (options.phase_steps) {
    distances.push_back(1);
    if (options.phase_step_far > 1) distances.push_back(options.phase_step_far);
  }
  // On the CPU, without autograd, the selection runs in one pass over the spectra (on one
  // thread at a 96-px input at::topk and the phase steps' gathers were two thirds of the
  // layer's time); it gives the tensor path's maps bit for bit. Local peaks and the mode shape
  // keep the tensor path.
  const bool one_pass = options.one_pass && x.device().is_cpu() && !options.local_peaks &&
                        !options.mode_shape && !(at::GradMode::is_enabled() && x.requires_grad());
  if (one_pass) {
    spectrum = spectrum.contiguous();
    const std::vector<double> eps = options.phase_steps ? PhaseStepEps(spectrum, nb) : std::vector<double>();
    SpectralPeaks peaks = SpectralPeaksCpu(spectrum, window.square().sum(), first, candidates, k,
                                           frame_rate / static_cast<double>(length), nb, c, h, w, distances, eps);
    SpectralMaps maps{peaks.power, peaks.frequency, peaks.phase, at::Tensor()};
    if (options.still_floor != 0)
      ZeroStillPixels(x, CandidatePeriodogram(spectrum, window, first, candidates), window, options.still_floor, maps);
    return maps;
  }
  const at::Tensor periodogram = CandidatePeriodogram(spectrum, window, first, candidates);
  at::Tensor ranked = periodogram;
  if (options.local_peaks) {
    // A bin is a peak when no neighbour is higher (>= on the left, > on the right, so a flat
    // top counts once); beyond the ends the spectrum counts as -infinity.
    at::Tensor pad = at::full({periodogram.size(0), 1}, -std::numeric_limits<double>::infinity(),
                              periodogram.options());
    at::Tensor left = at::cat({pad, periodogram.narrow(1, 0, candidates - 1)}, 1);
    at::Tensor right = at::cat({periodogram.narrow(1, 1, candidates - 1), pad}, 1);
    at::Tensor is_peak = periodogram.ge(left).logical_and(periodogram.gt(right));
    ranked = at::where(is_peak, periodogram, at::full_like(periodogram, -1.0));
  }
  auto [score, bin] = at::topk(ranked, k, /*dim=*/1, /*largest=*/true, /*sorted=*/true);
  // topk's values are the selected bins' powers (a non-peak's -1 only where no peak was left).
  at::Tensor power = score;
  at::Tensor frequency = (bin + first).to(x.scalar_type()) * (frame_rate / static_cast<double>(length));
  if (options.local_peaks) {
    // Slots no peak filled (score -1), and peaks of a still pixel (power 0), read as no motion.
    at::Tensor missing = score.le(0);
    power = score.masked_fill(missing, 0.0);
    frequency = frequency.masked_fill(missing, 0.0);
  }
  auto to_map = [&](const at::Tensor& t) {
    return t.reshape({nb, c, h, w, k}).permute({0, 1, 4, 2, 3}).reshape({nb, c * k, h, w});
  };
  SpectralMaps maps{to_map(power), to_map(frequency), at::Tensor(), at::Tensor()};
  if (options.phase_steps) maps.phase = PhaseSteps(spectrum, bin.narrow(1, 0, 1) + first, nb, c, h, w, distances);
  if (options.mode_shape) maps.mode = ModeShape(spectrum, periodogram, first, nb, c, h, w);
  if (options.still_floor != 0) ZeroStillPixels(x, periodogram, window, options.still_floor, maps);
  return maps;
}

at::Tensor StackSpectralMaps(const SpectralMaps& maps) {
  return at::cat({maps.power, maps.frequency}, 1);
}

}  // namespace clothwind::learn
