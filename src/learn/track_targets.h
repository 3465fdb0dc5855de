// Auxiliary training targets from a clip's tracks (DIR/<name>/tracks.json, written by
// `clothwind make-dataset --tracks`): per material point of a grid, where it sits in the sample
// and how much it moves at the lowest frequencies — what the window oracle reads the wind from
// (docs/sdn-experiments.md). A network trained to regress them beside the wind (--aux-tracks)
// gets dense supervision of the cloth's motion, where a clip otherwise gives one number.
// Torch-free.
#ifndef CLOTHWIND_LEARN_TRACK_TARGETS_H_
#define CLOTHWIND_LEARN_TRACK_TARGETS_H_

#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

namespace clothwind::learn {

// A clip's tracks as stored.
struct Tracks {
  int cols = 0, rows = 0;      // the grid of material points (points = cols · rows)
  int width = 0, height = 0;   // the frames' size [px]
  int frames = 0;
  // frames x points x 2 continuous image coordinates [px] (x right, y down), row-major.
  std::vector<float> xy;
  int points() const { return cols * rows; }
};

// Reads a tracks.json file (format "clothwind-tracks", version 1). Throws std::runtime_error
// naming the file and the field that is missing or inconsistent.
Tracks ReadTracks(const std::filesystem::path& file);

// DFT bins whose amplitudes are targets: 1..kTrackBins (0.83-4.2 Hz for 30 frames at 25 Hz,
// where a flag flaps).
constexpr int kTrackBins = 5;
// Targets per point: for each image coordinate, its window mean and its log amplitude at each bin.
constexpr int kTargetsPerPoint = 2 * (1 + kTrackBins);

// The targets of one sample, for the window, crop and flip that made it (learn::Sample).
// Inputs: tracks; first, frames  the sample's window; crop  the square it shows, in pixels of
//   frames of side `source_side` (the clip's own frames, or a frame cache's resized squares;
//   the tracks, given for tracks.width, are scaled to it); flipped  whether it was mirrored.
// Output: points · kTargetsPerPoint values, point-major; per point (u, v) means, then u's and v's
//   log(1e-4 + A_j) for j = 1..kTrackBins. u, v: position in the sample scaled to [-1, 1]
//   (u right, negated when flipped; v down); A_j = |Σ_t w_t (u_t - ū) e^{-2πi jt/T}| / Σ_t w_t,
//   w the periodic Hann window (the spectral layer's), so a sinusoid of amplitude a at bin j reads a / 2.
// Throws std::invalid_argument when the window is outside the tracks or the frames are not square.
std::vector<float> TrackTargets(const Tracks& tracks, int first, int frames, const cv::Rect& crop, int source_side,
                                bool flipped);

// Per-target mean and standard deviation over `targets` (rows of one length), to standardise
// the targets so that each weighs about as much in the loss whatever its units. A constant target
// gets std 1 (it then adds only its mean's error).
struct TargetScale {
  std::vector<float> mean, std;
};
TargetScale ScaleOf(const std::vector<std::vector<float>>& targets);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_TRACK_TARGETS_H_
