// The architecture hyper-parameters of a wind network, saved as JSON beside its weights so the
// node, the eval verb and a resumed training rebuild exactly the network that was trained.
#ifndef CLOTHWIND_LEARN_MODEL_CONFIG_H_
#define CLOTHWIND_LEARN_MODEL_CONFIG_H_

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "learn/dataset.h"
#include "learn/spectral_layer.h"

namespace clothwind::learn {

struct ModelConfig {
  // "sdn" (spectral layer + ResNet-18), "resnet18" (frames as channels) or "lstm" (Yang et al.'s
  // recurrent baseline: a ResNet-18 trunk per frame, an LSTM over the frames' features)
  std::string arch = "sdn";
  int frames = 30;           // N_t, input frames per clip
  int channels = 1;          // C, channels per frame: 1 (greyscale, as the seed), 3 with flow or colour
  // Each frame's optical flow from the one before as two more channels (SampleOptions::flow):
  // the spectral layer then reads how far the cloth moves, not only how its texture flickers.
  bool flow = false;
  // With flow: the side [px] the flow is computed at before it is resized to input_size (0:
  // input_size; SampleOptions::flow_size).
  int flow_size = 0;
  // Colour frames, Y Cr Cb, instead of grey ones (SampleOptions::colour: the edges between two
  // colours of one grey); not with flow.
  bool colour = false;
  int k = 3;                 // SDN: spectral peaks kept per pixel (2kC trunk input channels)
  bool include_dc = false;   // SDN: the DC bin among the candidate peaks (no detrend)
  bool mean_map = false;     // SDN: the clip's per-pixel temporal mean as C more trunk channels
  int dft_size = 0;          // SDN: DFT length, zero-padded beyond N_t (0: N_t; SpectralOptions)
  bool local_peaks = false;  // SDN: the k strongest local maxima instead of the k strongest bins
  bool phase_steps = false;  // SDN: 4C more channels, the strongest peak's phase step to the neighbours
  int phase_step_far = 0;    // SDN with phase_steps: 4C more, the step over this many pixels (0: none)
  // SDN: selected bins at or below this times the clip's mean periodogram (or the detrend's
  // rounding) read power and frequency 0 (SpectralOptions::still_floor; 0: off, as every model
  // trained before it).
  double still_floor = 0.0;
  bool mode_shape = false;   // SDN: 2C more, each pixel's amplitude at the clip's dominant frequency
                             // relative to the pixel that moves most (SpectralOptions::mode_shape)
  // SDN: the spectral maps are computed on the input_size clip and average-pooled by this factor
  // before the trunk, so fine texture's motion reaches a trunk that costs what input_size /
  // spectral_pool would (1: no pooling). input_size must be a multiple of it.
  int spectral_pool = 1;
  // The trunk's 3×3 stride-2 max pool after its stem, as ResNet-18's. At 64 px the stem and the
  // pool leave 16 px for the first stage; without the pool the stages keep 32 px, at about four
  // times their cost (a small input's detail is what the pool throws away).
  bool stem_pool = true;
  // Two more trunk channels, each pixel's column and row scaled to (-1, 1) (CoordConv): with the
  // camera aimed at the flag's rest centre, where in the frame the flag moves says how far it
  // droops, and convolutions followed by average pooling see where only through the zero padding.
  bool coord_maps = false;
  // SDN: this many of the clip's own frames, evenly spaced over it, as N·C more trunk channels
  // after the spectral maps (0: none). Why: the spectral layer keeps each pixel's strongest
  // frequencies and their power but not where the cloth is at any instant, which the window
  // oracle's point tracks hold (docs/sdn-experiments.md, "The frames beside the spectra").
  int frame_channels = 0;
  double dropout = 0.0;      // dropout probability on the trunk's pooled features while training
  // The wind head: 0 reads the pooled features linearly (ResNet's); N > 0 puts a hidden layer of
  // N ReLU units before it. Why: the window oracle reads the wind from its features with boosted
  // trees, not a linear map (docs/sdn-experiments.md, "How much one window can tell").
  int head_hidden = 0;
  // Training only: a second head on the trunk's pooled features with this many outputs, which
  // training fits to the clip's track targets (learn/track_targets.h, --aux-tracks); 0: none.
  // The wind estimate never reads it, so a model with one predicts as one without.
  int aux_outputs = 0;
  // Training only, with aux_outputs: the points' window-mean positions among the auxiliary targets
  // come from heat maps on the trunk's stage maps (learn/point_maps.h, --point-maps) instead of the
  // linear head; the count of points P (0: none). Why: a linear head on pooled features knows
  // them to ~1.1 px of 64, where the wind needs a fraction of a pixel.
  int point_maps = 0;
  // Training flipped clips left to right at random (the seed's; train --no-flip: false). A model
  // trained without flips knows only flags flying right, as FlagSim's do, so the node turns clips
  // of flags flying left round for it by default (DefaultFlagFlies).
  bool flips_in_training = true;
  double frame_rate = 25.0;  // [Hz] of the clips the model reads
  int width = 64;            // ResNet-18 base width (64 as the original; 16 trains on a CPU)
  int input_size = 112;      // side of the square input [px] (224 as the seed, 112 for a CPU)
  double label_mean = 0.0;   // [m/s] the network regresses (v - label_mean) / label_std
  double label_std = 1.0;    // [m/s]
  // Factor on the predicted standard deviation, fitted on the validation split after training
  // (clothwind export-model --calibrate-std; CalibrationScale): a network that fits its training
  // clips better than new ones learns a variance that is too small for new ones. 1: as trained.
  double std_scale = 1.0;

  // The spectral layer's options for this model (k, frame rate, DC, DFT length, peaks).
  SpectralOptions Spectral() const;
  // The spectral layer's DFT length: dft_size, or N_t when it is 0.
  int DftLength() const { return dft_size == 0 ? frames : dft_size; }
  // Frequency bins the spectral layer offers this model (what k may be at most).
  int SpectralCandidates() const;
  // phase_step_far is 0, or a distance of at least 2 pixels with phase_steps on.
  bool PhaseStepFarIsValid() const;
  // mode_shape is off, or on an SDN without include_dc (undetrended, the still image would be
  // the dominant mode; SpectralOptions::mode_shape).
  bool ModeShapeIsValid() const { return !mode_shape || (arch == "sdn" && !include_dc); }
  // The first of the spectral layer's own options (mean_map, phase_steps, include_dc, dft_size,
  // local_peaks) that is set on a model without one (resnet18, lstm), by its field name; "" when
  // none is. Why: a baseline given them was built without them while its model.json said otherwise.
  std::string SpectralOptionOffSdn() const {
    if (arch == "sdn") return "";
    if (mean_map) return "mean_map";
    if (phase_steps) return "phase_steps";
    if (include_dc) return "include_dc";
    if (dft_size != 0) return "dft_size";
    if (local_peaks) return "local_peaks";
    if (still_floor != 0) return "still_floor";
    return "";
  }
  // spectral_pool is >= 1, divides input_size, and is 1 unless the model is an SDN.
  bool SpectralPoolIsValid() const;
  // frame_channels is 0, or 1..frames on an SDN.
  bool FrameChannelsAreValid() const {
    return frame_channels == 0 || (arch == "sdn" && frame_channels >= 1 && frame_channels <= frames);
  }
  // The frames an SDN with frame_channels N shows its trunk: N indices evenly spaced over
  // 0..frames-1, rounded (first and last included; N = 1: the middle frame). Empty for N = 0.
  std::vector<int64_t> FrameChannelIndices() const;

  // How the node turns clips for this model unless told (~flag_flies): kAuto for a model trained
  // without flips, kRight (as filmed) for one that has seen flags fly both ways.
  FlagFlies DefaultFlagFlies() const { return flips_in_training ? FlagFlies::kRight : FlagFlies::kAuto; }
  // Channels entering the ResNet trunk: 2kC (+C with mean_map, +4C or 8C with phase steps, +2C
  // with mode_shape, +N·C with frame_channels N) for the SDN, N_t·C for the frame-stack baseline, C for the recurrent one
  // (its trunk reads one frame at a time); +2 with coord_maps for every architecture.
  int TrunkInputChannels() const;
  // How a clip becomes this model's input: frames, input size and flow set, no augmentation
  // (evaluation's and the node's; training adds its augmentation to these).
  SampleOptions Sampling() const;
  // The channels per frame that `flow` or `colour` imply (1 or 3): Sampling().channels().
  int ChannelsForInput() const { return Sampling().channels(); }
  // colour is off, or on a model without flow (the flow is computed from the grey frames).
  bool ColourIsValid() const { return !(colour && flow); }
  // point_maps needs a trunk that sees a whole clip (not lstm's per-frame one) and an auxiliary head
  // with every point's kTargetsPerPoint targets.
  bool PointMapsAreValid() const;
  // flow_size is 0, or a side of at least 16 px on a model with flow.
  bool FlowSizeIsValid() const { return flow_size == 0 || (flow && flow_size >= 16); }
  // A short name for logs and messages, e.g. "sdn-k3-w64-112-30f" ("…-flow-…" with flow, "sdn-k3m-…" with mean_map,
  // "sdn-k3dc-…" with include_dc, "sdn-k3d120p-…" with dft_size 120 and local_peaks, "…s-" with phase_steps,
  // "…s4-" with phase_step_far 4, "…o-" with mode_shape, "…z-" with a still_floor, "…s/2-" with spectral_pool 2, "…-xy-" with
  // coord_maps, "…-ycc-" with colour, "…-h256-" with head_hidden 256, "…s+f10-" with frame_channels 10).
  std::string Name() const;
  // Table 1's "input modality", e.g. "30x112x112" ("30x3x64x64" with flow's or colour's three channels).
  std::string Modality() const;
};

// True for an architecture this version builds ("sdn", "resnet18", "lstm").
bool IsKnownArch(const std::string& arch);

// The model.json format this build writes and reads: an option that changes what a network
// computes must raise it, so an older clothwind refuses the file instead of ignoring the option.
constexpr int kModelFormatVersion = 1;

// JSON round trip; FromJson throws std::runtime_error naming the missing or invalid field, a
// field it does not know, or a newer "version" (`where` names the file for the message). Every
// configuration it returns passes the WindNet constructor's checks (k within the DFT's bins, at
// least 2 frames on an SDN, FrameChannelsAreValid(), ...).
nlohmann::json ToJson(const ModelConfig& config);
ModelConfig ModelConfigFromJson(const nlohmann::json& j, const std::string& where);

// The JSON file that goes with a weights file: "run/model.pt" -> "run/model.json".
std::filesystem::path ConfigPathFor(const std::filesystem::path& weights);

// Throws std::runtime_error naming `weights` when it is a folder or no file, before its JSON is
// looked for: a folder or a mistyped name given as the model was told "<name>.json: cannot open".
// Inputs: weights  the weights file given; what  what it should be ("a model", "a fly judge").
void RequireWeightsFile(const std::filesystem::path& weights, const std::string& what);

// Writes `text` to `path` atomically (temporary file in the same folder, then rename).
void WriteFileAtomically(const std::filesystem::path& path, const std::string& text);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_MODEL_CONFIG_H_
