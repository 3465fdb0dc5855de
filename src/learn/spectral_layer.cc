#include "learn/spectral_layer.h"

#include <stdexcept>
#include <string>

#include <ATen/ATen.h>

namespace clothwind::learn {

SpectralMaps SpectralDecomposition(const at::Tensor& x, int k, double frame_rate, bool include_dc) {
  if (x.dim() != 5) {
    throw std::invalid_argument("SpectralDecomposition: expected a [N_b, C, N_t, H, W] tensor, got " +
                                std::to_string(x.dim()) + " dimensions");
  }
  const int64_t nb = x.size(0), c = x.size(1), nt = x.size(2), h = x.size(3), w = x.size(4);
  if (nt < 2) throw std::invalid_argument("SpectralDecomposition: N_t must be at least 2");
  const int64_t first = include_dc ? 0 : 1;
  const int64_t candidates = nt / 2 + 1 - first;
  if (k < 1 || k > candidates) {
    throw std::invalid_argument("SpectralDecomposition: k = " + std::to_string(k) + " but N_t = " +
                                std::to_string(nt) + " offers " + std::to_string(candidates) +
                                " frequency bins");
  }
  if (!(frame_rate > 0)) throw std::invalid_argument("SpectralDecomposition: frame_rate must be > 0");
  // [N_b C H W, N_t]: one row per pixel signal.
  at::Tensor signals = x.permute({0, 1, 3, 4, 2}).reshape({-1, nt});
  at::Tensor window = at::hann_window(nt, /*periodic=*/true, x.options());
  // Without the DC bin the pixel's mean is removed first (else it leaks through the Hann window
  // into bin 1); with it, the signal is taken as it is (Algorithm 1 verbatim), so the DC bin
  // carries the pixel's windowed mean brightness.
  if (!include_dc) signals = signals - signals.mean(1, /*keepdim=*/true);
  at::Tensor spectrum = at::fft_rfft(signals * window, c10::nullopt, /*dim=*/1);
  at::Tensor periodogram = (at::real(spectrum).square() + at::imag(spectrum).square()) /
                           window.square().sum();
  periodogram = periodogram.narrow(1, first, candidates);
  auto [power, bin] = at::topk(periodogram, k, /*dim=*/1, /*largest=*/true, /*sorted=*/true);
  at::Tensor frequency = (bin + first).to(x.scalar_type()) * (frame_rate / static_cast<double>(nt));
  auto to_map = [&](const at::Tensor& t) {
    return t.reshape({nb, c, h, w, k}).permute({0, 1, 4, 2, 3}).reshape({nb, c * k, h, w});
  };
  return {to_map(power), to_map(frequency)};
}

at::Tensor StackSpectralMaps(const SpectralMaps& maps) {
  return at::cat({maps.power, maps.frequency}, 1);
}

}  // namespace clothwind::learn
