// The spectral decomposition layer of the SDN (seed supplementary, Algorithm 1): every pixel's
// signal along time is Hann-windowed and Fourier transformed; the k strongest periodogram bins
// and their frequencies become 2kC image channels that ordinary 2D convolutions can read.
#ifndef CLOTHWIND_LEARN_SPECTRAL_LAYER_H_
#define CLOTHWIND_LEARN_SPECTRAL_LAYER_H_

#include <ATen/core/Tensor.h>

namespace clothwind::learn {

// How the layer reads each pixel's spectrum (beyond Algorithm 1's k, frame rate and DC choice).
struct SpectralOptions {
  int k = 3;                // bins (or peaks) kept per pixel
  double frame_rate = 25.0; // [Hz] sampling rate of the clip (25 for FlagSim)
  bool include_dc = false;  // keep the DC bin among the candidates and do not detrend
  // DFT length L >= N_t (0: L = N_t, Algorithm 1). L > N_t zero-pads the windowed signal, which
  // samples the same spectrum every frame_rate / L Hz instead of every frame_rate / N_t: a
  // 30-frame clip's bins are 0.83 Hz apart, coarse beside a flag's flapping frequency, which
  // grows with the wind. The periodogram's scale is unchanged (normalised by sum w_n^2).
  int dft_size = 0;
  // Keep the k strongest local maxima of the periodogram (I_j >= I_{j-1} and I_j > I_{j+1}; the
  // ends count when higher than their one neighbour) instead of the k strongest bins: on a padded
  // DFT the strongest bins all sit on the main peak's lobe, so bins would repeat one peak k
  // times. A pixel with fewer than k peaks of positive power gets power 0 and frequency 0 in the
  // missing slots.
  bool local_peaks = false;
  // Also return SpectralMaps::phase: how the strongest peak's phase changes to the next pixel.
  // The spectral maps say how fast each pixel moves, not where its motion is in its cycle; a
  // wave travelling along the flag shows as a steady phase step between neighbours (its
  // wavenumber), and the step, unlike the phase itself, does not depend on when the clip began.
  bool phase_steps = false;
  // With phase_steps, also the step over this many pixels (0: none; else >= 2). A long wave
  // turns by only a few degrees between neighbours, within the noise of one pixel's phase; over
  // several pixels the same wave turns further, so its wavenumber reads above that noise.
  int phase_step_far = 0;
  // Also return SpectralMaps::mode: every pixel's complex amplitude at the clip's dominant
  // frequency, relative to the phase of the pixel that moves most. Phase steps read the wave
  // between neighbours, where a wave as long as the flag turns by less than one pixel's phase
  // noise; against one reference the whole flag's phase ramp shows at once, as stripes whose
  // spacing is the wavelength (with the frequency, the wave's speed, which grows with the wind).
  bool mode_shape = false;
  // On the CPU, select the peaks and phase steps in one pass over the spectra
  // (learn/spectral_peaks_cpu.h) instead of through tensor ops: the same maps bit for bit, in
  // less time. The tensor ops run anyway on other devices, with autograd (a clip that requires
  // grad), with local_peaks and with mode_shape; false asks for them here too (to compare).
  bool one_pass = true;
  // Still pixels read no motion: a selected bin whose power is at most still_floor times the
  // clip's mean periodogram (per example, over its C·H·W pixels and candidate bins), or at most
  // the power of the detrend's rounding, (N_t · ε · max|x|)² / Σw² with ε the dtype's epsilon, reads
  // power 0 and frequency 0, as local_peaks' empty slots do. Why: a still pixel's spectrum is zeros or
  // rounding noise, whose top k is arbitrary (8.33 Hz or 0.83 Hz on the CPU, index order on
  // CUDA), and the frequency map reached the network ungated. 0: off, as models trained before
  // the option (they read those frequencies); `clothwind train` uses 1e-6.
  double still_floor = 0.0;
};

// Power and frequency maps of a batch of clips.
struct SpectralMaps {
  // [N_b, kC, H, W] periodogram of the selected bins, |X_j|² / Σw² (unit: input² · samples: a
  // cosine of amplitude A at an interior bin reads A² N_t / 6 with the periodic Hann window, 4 times
  // that at Nyquist; one-sided bins are not doubled, which is one scale at a fixed N_t)
  at::Tensor power;
  at::Tensor frequency;  // [N_b, kC, H, W] their frequencies [Hz]
  // With SpectralOptions::phase_steps, else undefined: [N_b, 4C, H, W], per input channel c the
  // channels 4c..4c+3 = cos, sin of the step to the right (x+1), cos, sin of the step down (y+1):
  // with X(p) the DFT of pixel p at p's strongest selected bin, and X(q) that of the neighbour q
  // at the same bin, X(p)·conj(X(q)) / (|X(p)||X(q)| + ε), ε = 1e-6 · the clip's mean |X|² (each clip its own, whatever it is batched with)
  // (so still pixels read ~0). A wave e^{i(ωt − κx)} reads (cos κ, sin κ). The last column's
  // right step and the last row's down step are 0. With phase_step_far = D, [N_b, 8C, H, W]:
  // channels 4C + 4c..4C + 4c+3 are the same steps to x+D and y+D (a wave reads (cos κD, sin κD)),
  // 0 in the last D columns / rows.
  at::Tensor phase;
  // With SpectralOptions::mode_shape, else undefined: [N_b, 2C, H, W], per input channel c the
  // channels 2c, 2c+1 = real and imaginary part of X(p)·conj(R) / (|R| · rms), where X(p) is
  // pixel p's DFT at the clip's dominant bin j* (the candidate bin of largest periodogram summed
  // over all H·W pixels of that channel), R = X(p*) at the pixel p* of largest |X(p)|, and
  // rms = sqrt(mean_p |X(p)|²) (plus 1e-30). So p* reads (|X(p*)|/rms, 0), a still pixel (0, 0),
  // a wave A(p) e^{i(ωt − κ·p)} at its bin reads A(p)/rms · e^{−iκ·(p − p*)}, whatever the clip's
  // start time. Refused with include_dc (undetrended, the still image would be the mode).
  // A per-clip feature: unlike the other maps it changes when a crop removes p* or
  // much of the motion (it still commutes with flips, and with crops that keep p* and the rms).
  at::Tensor mode;
};

// The spectral decomposition of a batch of clips (Algorithm 1), batched on the input's device.
//
// Per pixel signal x_n (n = 0..N_t-1): unless include_dc, the pixel's temporal mean m is removed
// (a constant detrend, as scipy.signal.periodogram does: otherwise a bright pixel's mean leaks
// through the Hann window into bin 1); with include_dc, m = 0 and the signal is transformed as it
// is (the seed's Algorithm 1). y_n = w_n (x_n - m) with the periodic Hann window
// w_n = 0.5 - 0.5 cos(2π n / N_t); X_j = Σ_n y_n e^{-2πi jn/N_t} (one-sided, j = 0..N_t/2);
// periodogram I_j = |X_j|² / Σ_n w_n²; the k largest I_j in descending order (the order of
// exactly equal powers is unspecified) and their frequencies f_j = j · frame_rate / N_t.
// The DC bin (j = 0) is excluded unless include_dc: it carries no motion, only the pixel's mean
// brightness (squared), which is mostly the strongest bin and so takes one of the k slots.
// Channel c·k + i of either map is the i-th strongest bin of input channel c.
//
// Inputs:
//   x           [N_b, C, N_t, H, W] floating tensor (any device)
//   k           number of bins to keep, 1 ≤ k ≤ number of candidate bins (N_t/2 or N_t/2+1)
//   frame_rate  sampling rate of the clip [Hz] (25 for FlagSim)
//   include_dc  keep the DC bin among the candidates and do not detrend
// Outputs:
//   the two maps, each [N_b, kC, H, W], same dtype and device as x
// Throws std::invalid_argument on a wrong rank, N_t < 2 or an impossible k.
SpectralMaps SpectralDecomposition(const at::Tensor& x, int k, double frame_rate,
                                   bool include_dc = false);

// The same with SpectralOptions: options.dft_size = L pads each windowed signal with zeros to L
// samples, so X_j = sum_n y_n e^{-2 pi i jn/L}, j = 0..L/2, and f_j = j frame_rate / L; with
// options.local_peaks only local maxima compete for the k slots. The defaults are Algorithm 1.
// Inputs/outputs as above; throws std::invalid_argument also for dft_size in (0, N_t) and for a
// still_floor that is negative or not finite.
SpectralMaps SpectralDecomposition(const at::Tensor& x, const SpectralOptions& options);

// Algorithm 1's output as one image: [power, frequency] concatenated along channels,
// [N_b, 2kC, H, W].
at::Tensor StackSpectralMaps(const SpectralMaps& maps);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_SPECTRAL_LAYER_H_
