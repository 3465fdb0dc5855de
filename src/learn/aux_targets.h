// The auxiliary targets a run with --aux-tracks trains its second head on, for a set of clips:
// each clip's tracks and the scale that standardises the targets. Training builds them from its
// train split; `clothwind eval --track-head` rebuilds the same scale to read the head's outputs
// back in pixels. Torch-free.
#ifndef CLOTHWIND_LEARN_AUX_TARGETS_H_
#define CLOTHWIND_LEARN_AUX_TARGETS_H_

#include <vector>

#include <opencv2/core.hpp>

#include "learn/dataset.h"
#include "learn/track_targets.h"

namespace clothwind::learn {

struct AuxTargets {
  std::vector<Tracks> tracks;  // one per clip, in the clips' order
  int phase_bins = 0;          // TrackTargets' phase_bins (TrainOptions::aux_phase_bins)
  bool world = false;          // WorldTrackTargets follow TrackTargets' (TrainOptions::aux_world)
  TargetScale scale;           // per target, over the clips' evaluation windows and their mirrors
  int outputs() const { return static_cast<int>(scale.mean.size()); }
};

// One sample's auxiliary targets, unscaled: TrackTargets', then with `world` WorldTrackTargets'.
// Inputs as TrackTargets (first, frames the window; crop in pixels of frames of side source_side).
std::vector<float> AuxTargetsOf(const Tracks& tracks, int first, int frames, const cv::Rect& crop, int source_side,
                                bool flipped, int phase_bins, bool world);

// Reads every clip's tracks.json and scales the targets by those of the clips' evaluation
// windows (options.frames centred, the centred square), as they are and mirrored (the training
// windows' augmentations).
// Throws std::runtime_error naming the first clip without tracks, or with tracks that do not fit
// it (other frames, size or grid than the first clip's; with `world`: no positions).
AuxTargets ReadAuxTargets(const std::vector<ClipInfo>& clips, const SampleOptions& options, int phase_bins,
                          bool world);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_AUX_TARGETS_H_
