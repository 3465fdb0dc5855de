// How well a network's auxiliary track head (--aux-tracks) knows where the cloth's points are and
// how they move, in the targets' own units: the window-mean positions in pixels of the network's
// input, the motion as log amplitudes. The track oracle (scripts/track-oracle) measures how the
// wind's error grows with a tracker's error in the same pixels, so the two together place a
// network on that curve (docs/sdn-experiments.md, "What the head knows of the points").
#ifndef CLOTHWIND_LEARN_TRACK_HEAD_EVAL_H_
#define CLOTHWIND_LEARN_TRACK_HEAD_EVAL_H_

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "learn/model_config.h"

namespace clothwind::learn {

struct TrackHeadReport {
  ModelConfig config;
  std::string split;
  int points = 0;
  int window = 0;  // frames of the window the targets are of (config.frames unless asked otherwise)
  std::vector<std::string> names;  // each clip, in the split's order
  std::vector<double> wind;        // [m/s] each clip's true wind
  // [clips][config.aux_outputs] the head's outputs unstandardised, and the targets of the same
  // evaluation window (AuxTargetsOf: centred window, centred square, not mirrored).
  std::vector<std::vector<float>> predicted, truth;
  // Window-mean positions: rms error over clips and points [px of the input_size input], per
  // image axis (x right, y down), and the fraction of their variance over clips and points the
  // head explains (1 - mse / var).
  double position_rmse_x = 0, position_rmse_y = 0, position_r2 = 0;
  // Per DFT bin j = 1..kTrackBins: rms error of the points' log amplitudes (both axes), and R².
  std::vector<double> amplitude_rmse, amplitude_r2;
  // Mean over clips and outputs of the squared error in standardised units: AuxLoss on this split
  // (the training log's train_aux_loss is the same figure on augmented training windows).
  double standardised_mse = 0;
  double seconds = 0;
};

// Runs the head of `model` (model.pt + model.json of a training run, not an exported file: export
// drops the head) over one split of `data`, with the targets standardised as training did: by the
// scale of the dataset's train split (ReadAuxTargets), with the run's phase bins and world targets
// read from state.json beside the model (none when it is absent).
// Inputs: threads  torch threads; batch  clips per forward pass; progress  (done, total) per batch;
//   window  0: the model's own frames (config.frames, centred); a multiple T of config.frames: the
//           centred T-frame window read as T / config.frames consecutive inputs whose outputs are
//           averaged, against the T-frame window's targets. A per-frame network (--frames 1) read
//           with window 30 gives the window-mean positions a tracker would give the SDN's window;
//           its amplitudes are then its own windows' (none for one frame), not the window's.
// Throws std::runtime_error naming the model when it has no head, the state file when the
// dataset's tracks give another number of targets than the head has, and the clip without tracks.
TrackHeadReport EvaluateTrackHead(const std::filesystem::path& model, const std::filesystem::path& data,
                                  const std::string& split, int threads, int batch,
                                  const std::function<void(int, int)>& progress = {}, int window = 0);

// What EvaluateTrackHead refuses that can be known before any data is read: a model without a
// head, a window that is not 0 or a multiple of its frames, a state.json whose options are of
// another type. Throws as EvaluateTrackHead would (eval ran a whole evaluation first, then threw
// and wrote none of its results).
void CheckTrackHead(const std::filesystem::path& model, int window);

// The report's figures as lines of text (positions in px of the input, amplitudes per bin).
std::string TrackHeadTable(const TrackHeadReport& report);

// One line per clip: name, true wind [m/s], then the predicted and the true targets (each
// config.aux_outputs values, TrackTargets' order), tab-separated, after a '#' header line naming
// the columns' groups; written atomically. For readers such as scripts/track-oracle's.
void WriteTrackHeadRows(const TrackHeadReport& report, const std::filesystem::path& file);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_TRACK_HEAD_EVAL_H_
