#include "learn/spectral_peaks_cpu.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include <ATen/ATen.h>
#include <ATen/AccumulateType.h>
#include <ATen/Parallel.h>
#include <c10/util/complex.h>

namespace clothwind::learn {

namespace {

// at::topk's ordering on the CPU (torch 1.13, aten/src/ATen/native/TopKImpl.h): (value, index)
// pairs in the accumulate type, NaN above everything, else the larger first; std::partial_sort
// when k·64 <= n, else std::nth_element at k−1 and std::sort of the k−1 before it. Equal powers
// (a still pixel's zeros) leave these algorithms in an order that only their steps fix; taking the
// same steps keeps the frequencies of still pixels as the tensor path gave them to the networks
// trained on it.
template <typename acc_t>
bool RanksAbove(const std::pair<acc_t, int64_t>& a, const std::pair<acc_t, int64_t>& b) {
  return (std::isnan(a.first) && !std::isnan(b.first)) || a.first > b.first;
}

template <typename acc_t>
void TopKAsAten(std::vector<std::pair<acc_t, int64_t>>& queue, int64_t k) {
  const int64_t n = static_cast<int64_t>(queue.size());
  if (k * 64 <= n) {
    std::partial_sort(queue.begin(), queue.begin() + k, queue.end(), RanksAbove<acc_t>);
  } else {
    std::nth_element(queue.begin(), queue.begin() + k - 1, queue.end(), RanksAbove<acc_t>);
    std::sort(queue.begin(), queue.begin() + k - 1, RanksAbove<acc_t>);
  }
}

// The k largest of `power` (n values) in descending order into `top`, when that is one answer:
// the k+1 largest (or all n, if fewer) are finite and distinct, so no order among equal powers is
// left to choose and at::topk must give the same. Returns false otherwise (a still pixel's
// zeros), leaving the pixel to TopKAsAten. Each of the k+1 passes takes the largest value below
// the previous one and counts its copies, without branches: most pixels take this path, and a
// sort's mispredicted branches on random powers cost several times as much.
template <typename scalar_t, typename acc_t>
bool TopKIfDistinct(const scalar_t* power, int64_t n, int64_t k, std::pair<acc_t, int64_t>* top) {
  bool finite = true;
  for (int64_t j = 0; j < n; ++j) finite &= std::isfinite(power[j]);
  if (!finite) return false;
  const int64_t passes = std::min(k + 1, n);
  scalar_t below = std::numeric_limits<scalar_t>::infinity();
  for (int64_t i = 0; i < passes; ++i) {
    scalar_t best = -std::numeric_limits<scalar_t>::infinity();
    int64_t at = 0;
    for (int64_t j = 0; j < n; ++j) {
      const bool take = (power[j] > best) & (power[j] < below);  // & not &&: no branch
      best = take ? power[j] : best;
      at = take ? j : at;
    }
    int copies = 0;
    for (int64_t j = 0; j < n; ++j) copies += power[j] == best;
    if (copies != 1) return false;
    if (i < k) top[i] = {static_cast<acc_t>(best), at};
    below = best;
  }
  return true;
}

// Pixel a's spectrum at bin j against pixel b's at the same bin: cos and sin of their phase step,
// in the tensor path's operation order (each product and sum rounded as its own tensor op).
template <typename scalar_t>
std::pair<scalar_t, scalar_t> PhaseStep(const c10::complex<scalar_t>& a, const c10::complex<scalar_t>& b,
                                        scalar_t eps) {
  const scalar_t ar = a.real(), ai = a.imag(), br = b.real(), bi = b.imag();
  const scalar_t power_a = ar * ar + ai * ai, power_b = br * br + bi * bi;
  const scalar_t norm = std::sqrt(power_a * power_b) + eps;
  const scalar_t real = ar * br + ai * bi, imag = ai * br - ar * bi;
  return {real / norm, imag / norm};
}

template <typename scalar_t>
void Select(const at::Tensor& spectrum, scalar_t weight_sum, int64_t first, int64_t candidates, int k,
            scalar_t bin_hz, int64_t nb, int64_t c, int64_t h, int64_t w, const std::vector<int64_t>& distances,
            const std::vector<double>& eps_per_example, SpectralPeaks& out) {
  using acc_t = at::acc_type<scalar_t, /*is_cuda=*/false>;
  const int64_t f = spectrum.size(1), hw = h * w, pixels = nb * c * hw;
  const int64_t blocks = static_cast<int64_t>(distances.size());
  const auto* s = spectrum.data_ptr<c10::complex<scalar_t>>();
  scalar_t* power = out.power.data_ptr<scalar_t>();
  scalar_t* frequency = out.frequency.data_ptr<scalar_t>();
  scalar_t* phase = blocks > 0 ? out.phase.data_ptr<scalar_t>() : nullptr;
  at::parallel_for(0, pixels, 4096, [&](int64_t begin, int64_t end) {
    std::vector<scalar_t> periodogram(candidates);
    std::vector<std::pair<acc_t, int64_t>> queue(candidates), top(k);
    for (int64_t p = begin; p < end; ++p) {
      const c10::complex<scalar_t>* row = s + p * f;
      for (int64_t j = 0; j < candidates; ++j) {
        const scalar_t re = row[first + j].real(), im = row[first + j].imag();
        periodogram[j] = (re * re + im * im) / weight_sum;
      }
      if (!TopKIfDistinct(periodogram.data(), candidates, k, top.data())) {
        for (int64_t j = 0; j < candidates; ++j) queue[j] = {static_cast<acc_t>(periodogram[j]), j};
        TopKAsAten(queue, k);
        std::copy(queue.begin(), queue.begin() + k, top.begin());
      }
      // p = (n·C + ci)·H·W + pixel; output channel ci·k + i of example n is plane (n·C + ci)·k + i.
      const int64_t plane = p / hw, pixel = p % hw;
      for (int i = 0; i < k; ++i) {
        power[(plane * k + i) * hw + pixel] = static_cast<scalar_t>(top[i].first);
        frequency[(plane * k + i) * hw + pixel] = static_cast<scalar_t>(top[i].second + first) * bin_hz;
      }
      if (blocks == 0) continue;
      const int64_t bin = top[0].second + first, n = plane / c, ci = plane % c;
      const scalar_t eps = static_cast<scalar_t>(eps_per_example[n]);
      const int64_t y = pixel / w, x = pixel % w;
      for (int64_t b = 0; b < blocks; ++b) {
        const int64_t d = distances[b];
        // Channel 4ci + q of block b of example n is plane n·4C·blocks + b·4C + 4ci + q.
        scalar_t* out_plane = phase + ((n * blocks + b) * 4 * c + 4 * ci) * hw + pixel;
        if (x + d < w) {
          const auto [cos, sin] = PhaseStep(row[bin], s[(p + d) * f + bin], eps);
          out_plane[0] = cos;
          out_plane[hw] = sin;
        }
        if (y + d < h) {
          const auto [cos, sin] = PhaseStep(row[bin], s[(p + d * w) * f + bin], eps);
          out_plane[2 * hw] = cos;
          out_plane[3 * hw] = sin;
        }
      }
    }
  });
}

}  // namespace

SpectralPeaks SpectralPeaksCpu(const at::Tensor& spectrum, const at::Tensor& weight_sum, int64_t first,
                               int64_t candidates, int k, double bin_hz, int64_t nb, int64_t c, int64_t h,
                               int64_t w, const std::vector<int64_t>& distances,
                               const std::vector<double>& eps) {
  if (!spectrum.device().is_cpu() || !spectrum.is_contiguous() || spectrum.dim() != 2 ||
      spectrum.size(0) != nb * c * h * w || !spectrum.is_complex()) {
    throw std::invalid_argument("SpectralPeaksCpu: expected a contiguous complex CPU tensor [N_b·C·H·W, F]");
  }
  if (first < 0 || candidates < 1 || first + candidates > spectrum.size(1) || k < 1 || k > candidates) {
    throw std::invalid_argument("SpectralPeaksCpu: candidates [" + std::to_string(first) + ", " +
                                std::to_string(first + candidates) + ") and k = " + std::to_string(k) +
                                " do not fit " + std::to_string(spectrum.size(1)) + " bins");
  }
  if (!distances.empty() && static_cast<int64_t>(eps.size()) != nb)
    throw std::invalid_argument("SpectralPeaksCpu: expected one phase-step eps per example (" + std::to_string(nb) +
                                "), got " + std::to_string(eps.size()));
  const at::ScalarType real_type = c10::toRealValueType(spectrum.scalar_type());
  const at::TensorOptions options = at::TensorOptions().dtype(real_type);
  SpectralPeaks out;
  out.power = at::empty({nb, k * c, h, w}, options);
  out.frequency = at::empty({nb, k * c, h, w}, options);
  if (!distances.empty()) out.phase = at::zeros({nb, 4 * c * static_cast<int64_t>(distances.size()), h, w}, options);
  AT_DISPATCH_FLOATING_TYPES(real_type, "SpectralPeaksCpu", [&] {
    Select<scalar_t>(spectrum, weight_sum.item<scalar_t>(), first, candidates, k, static_cast<scalar_t>(bin_hz),
                     nb, c, h, w, distances, eps, out);
  });
  return out;
}

}  // namespace clothwind::learn
