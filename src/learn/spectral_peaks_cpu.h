// The spectral layer's per-pixel selection on the CPU in one pass: each pixel's k strongest
// periodogram bins, their frequencies and the strongest bin's phase steps to its neighbours, read
// straight from the one-sided spectra. It computes what the layer's tensor path (at::topk, then
// PhaseSteps' narrows and gathers) computes, with the same arithmetic in the same order and the
// same ordering of equal powers, so its maps are the tensor path's bit for bit; it only leaves out
// that path's intermediate tensors, which made the selection two thirds of the layer's time at a
// 96-px input (docs/sdn.md, "Speed").
#ifndef CLOTHWIND_LEARN_SPECTRAL_PEAKS_CPU_H_
#define CLOTHWIND_LEARN_SPECTRAL_PEAKS_CPU_H_

#include <cstdint>
#include <vector>

#include <ATen/core/Tensor.h>

namespace clothwind::learn {

// Inputs:
//   spectrum    [N_b·C·H·W, F] complex (float or double), contiguous, on the CPU: one row per
//               pixel, pixel index ((n·C + c)·H + y)·W + x; the one-sided DFT of its windowed signal
//   weight_sum  Σ_n w_n² of the window (a 0-dim tensor of the spectrum's real type): the
//               periodogram is I_j = |X_j|² / weight_sum
//   first       spectrum bin of the first candidate (1 without the DC bin, else 0)
//   candidates  number of candidate bins from `first` (first + candidates <= F)
//   k           bins kept per pixel, 1 <= k <= candidates
//   bin_hz      frequency of one bin [Hz] (frame_rate / DFT length)
//   nb, c, h, w the batch's shape
//   distances   phase-step distances in pixels (empty: no phase steps), each >= 1
//   eps         ε of the phase steps' normalisation (SpectralMaps::phase), one per example (nb;
//               empty without phase steps)
// Outputs:
//   power       [N_b, kC, H, W] the k largest I_j of each pixel in descending order, channel c·k + i
//   frequency   [N_b, kC, H, W] their frequencies (j · bin_hz)
//   phase       [N_b, 4C·#distances, H, W] (undefined when `distances` is empty): per distance,
//               channels 4c..4c+3 = cos, sin of the step right, cos, sin of the step down, as
//               SpectralMaps::phase defines them; 0 where the neighbour is outside the image.
struct SpectralPeaks {
  at::Tensor power;
  at::Tensor frequency;
  at::Tensor phase;
};
SpectralPeaks SpectralPeaksCpu(const at::Tensor& spectrum, const at::Tensor& weight_sum, int64_t first,
                               int64_t candidates, int k, double bin_hz, int64_t nb, int64_t c, int64_t h,
                               int64_t w, const std::vector<int64_t>& distances,
                               const std::vector<double>& eps);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_SPECTRAL_PEAKS_CPU_H_
