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
  // frames x points x 3 positions in the simulator's frame [m] (FlagSim: x downwind, y across,
  // z up), row-major; empty for files written before they were stored.
  std::vector<float> world;
  int points() const { return cols * rows; }
};

// Reads a tracks.json file (format "clothwind-tracks", version 1; "world" optional). Throws
// std::runtime_error naming the file and the field that is missing or inconsistent.
Tracks ReadTracks(const std::filesystem::path& file);

// DFT bins whose amplitudes are targets: 1..kTrackBins (0.83-4.2 Hz for 30 frames at 25 Hz,
// where a flag flaps).
constexpr int kTrackBins = 5;
// Targets per point: for each image coordinate, its window mean and its log amplitude at each bin.
constexpr int kTargetsPerPoint = 2 * (1 + kTrackBins);
// Phase targets per point and phase bin (TrackTargets' phase_bins): u's and v's (re, im).
constexpr int kPhaseTargetsPerPointAndBin = 4;

// How many targets TrackTargets returns for `points` points and `phase_bins` phase bins.
inline int TrackTargetCount(int points, int phase_bins) {
  return points * (kTargetsPerPoint + kPhaseTargetsPerPointAndBin * phase_bins);
}

// The targets of one sample, for the window, crop and flip that made it (learn::Sample).
// Inputs: tracks; first, frames  the sample's window; crop  the square it shows, in pixels of
//   frames of side `source_side` (the clip's own frames, or a frame cache's resized squares;
//   the tracks, given for tracks.width, are scaled to it); flipped  whether it was mirrored.
// Output: TrackTargetCount(points, phase_bins) values: first points · kTargetsPerPoint, point-major; per point (u, v) means, then u's and v's
//   log(1e-4 + A_j) for j = 1..kTrackBins. u, v: position in the sample scaled to [-1, 1]
//   (u right, negated when flipped; v down); A_j = |Σ_t w_t (u_t - ū) e^{-2πi jt/T}| / Σ_t w_t,
//   w the periodic Hann window (the spectral layer's), so a sinusoid of amplitude a at bin j reads a / 2.
//   With phase_bins = B > 0 (at most kTrackBins), B · 4 values per point follow all points' blocks,
//   point-major, then bin-major: for j = 1..B, u's then v's (re, im) of
//   sqrt(A_j) · e^{i(φ_j - ψ_j)}, where φ_j is the coordinate's phase at bin j and ψ_j the phase of
//   the last point's v there (a fly corner, docs/datasets.md "Tracks"; ψ_j = 0 where it does not
//   move). Relative phases are what the window oracle reads a travelling wave by, and they do not
//   depend on when the window starts; the sqrt(A_j) weight fades them out where a point hardly moves
//   and its phase is noise.
// A window of one frame (a per-frame network's, --frames 1) has no motion: its amplitudes read
// log(1e-4) and its phases 0, so only the positions teach the head.
// Throws std::invalid_argument when the window is outside the tracks, the frames are not square or
// phase_bins is outside [0, kTrackBins].
std::vector<float> TrackTargets(const Tracks& tracks, int first, int frames, const cv::Rect& crop, int source_side,
                                bool flipped, int phase_bins = 0);

// Targets per point of WorldTrackTargets: for each of x, y, z its window mean and its log
// amplitude at each bin.
constexpr int kWorldTargetsPerPoint = 3 * (1 + kTrackBins);

// The targets of one sample from the points' positions (Tracks::world): where the cloth is and how
// it moves in metres, whatever camera filmed it. The window oracle reads the wind to ~0.19 m/s a
// window from these and to ~0.30 from the same points seen through FlagSim's cameras
// (docs/sdn-experiments.md, "How much one window can tell"): asking the network for them asks it
// to undo the camera.
// Inputs: tracks (with world); first, frames  the sample's window; flipped  whether it was mirrored.
// Output: points · kWorldTargetsPerPoint values, point-major; per point the x, y, z means [m], then
//   x's, y's and z's log(1e-4 + A_j) for j = 1..kTrackBins (A_j [m] as TrackTargets'). A mirrored
//   image is the mirrored scene, whose wind-aligned frame has y negated: flipping negates the y mean.
//   The crop changes nothing.
// Throws std::invalid_argument when the tracks have no positions or the window is outside them.
std::vector<float> WorldTrackTargets(const Tracks& tracks, int first, int frames, bool flipped);

// Per-target mean and standard deviation over `targets` (rows of one length), to standardise
// the targets so that each weighs about as much in the loss whatever its units. A constant target
// gets std 1 (it then adds only its mean's error).
struct TargetScale {
  std::vector<float> mean, std;
};
TargetScale ScaleOf(const std::vector<std::vector<float>>& targets);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_TRACK_TARGETS_H_
