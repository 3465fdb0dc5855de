// Training a wind network with the seed's recipe (supplementary section 4): Adam, lr 1e-2
// divided by 10 after half the epochs (20 of 40), weight decay 2e-3, optional gradient-norm
// clipping; random temporal offset, greyscale, multi-scale random crop, horizontal flip and
// per-clip normalisation. Torch-free interface.
#ifndef CLOTHWIND_LEARN_TRAIN_H_
#define CLOTHWIND_LEARN_TRAIN_H_

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "learn/evaluate.h"
#include "learn/model_config.h"

namespace clothwind::learn {

struct TrainProgress {
  int epoch = 0, epochs = 0;  // 1-based epoch being trained
  int step = 0, steps = 0;    // batches done in this epoch (0: the epoch starts), of
  double loss = 0;            // running mean training loss of this epoch
  // After the last step: validation clips done of all it reads this epoch (twice the split with a
  // weight average: the trained weights and their average); 0 of 0 while training.
  int val_done = 0, val_total = 0;
};

struct TrainOptions {
  ModelConfig model;                 // arch, frames, k, width, input_size (label stats filled in)
  std::filesystem::path data;        // dataset folder (docs/dataset.md); may be empty with init_only
  std::filesystem::path out;         // run folder: model.pt/json (best), checkpoint-eNNNN/, log.tsv, plot
  int epochs = 40;
  int batch = 16;
  double lr = 1e-2;
  std::string lr_schedule = "step";  // "step" (the seed's) or "cosine" (see LearningRateAt)
  int lr_decay_epoch = -1;           // step: epochs before lr /= lr_decay_factor; -1: epochs / 2
  double lr_decay_factor = 10;
  double weight_decay = 2e-3;
  // Multi-scale random crop (the seed's, after TSN): side of each training crop as a fraction of
  // the frame's shorter side, one drawn per clip. Evaluation always takes the whole square, so
  // scales below 1 also train on zoomed views that the test never shows.
  std::vector<double> crop_scales = {1.0, 0.875, 0.75, 0.66};
  // Random horizontal flips (the seed's); false trains on clips the way round they were filmed
  // (SampleOptions::flip).
  bool flip = true;
  double grad_clip = -1;             // max gradient norm; 0: off; < 0: the seed's (10 for lstm, else off)
  int threads = 2;                   // torch intra-op threads
  std::string device = "auto";       // cpu | cuda | auto
  bool resume = false;               // continue from out/state.json and the checkpoint it names
  // model.still_floor is the default, not asked for (train without --still-floor): a resumed run
  // keeps its own, so a run from before the option (0) resumes with the command it was given.
  bool still_floor_default = false;
  // Without resume, a folder that already holds a run (state.json or model.pt) is refused unless
  // this is set: rerunning a command after a crash without --resume replaced a day's run.
  bool overwrite = false;
  bool init_only = false;            // write an initialised (untrained) model and stop (not with resume)
  // Keep every frame decoded and resized in memory after its first read (learn/frame_cache.h):
  // the same samples, without rereading a dataset larger than the page cache each epoch.
  // Needs crop_scales = {1} and square frames; costs clips x frames x input_size^2 bytes.
  bool cache_frames = false;
  // Weight of the auxiliary loss (0: off): a second head regresses each training sample's
  // standardised track targets (learn/track_targets.h) from the dataset's tracks.json files, and
  // training minimises WindLoss + aux_tracks · AuxLoss. Every training clip needs its tracks.
  double aux_tracks = 0;
  // With aux_tracks > 0: also regress each point's phase relative to a fly corner's at DFT bins
  // 1..aux_phase_bins (TrackTargets' phase_bins; 0: none), the travelling wave the oracle reads.
  int aux_phase_bins = 0;
  // With aux_tracks > 0: also regress the points' positions and motion in metres
  // (WorldTrackTargets, from tracks.json's "world"): the cloth's shape whatever camera filmed it.
  bool aux_world = false;
  // With aux_tracks > 0: the points' window-mean positions come from a point map head
  // (ModelConfig::point_maps, learn/point_maps.h) instead of the linear head.
  bool point_maps = false;
  // Decay of an exponential moving average of the weights, updated after every step
  // (learn/weight_average.h, with its warm-up; 0: off). With it, validation reads
  // the average, model.pt is the average's best epoch and raw_model.pt the trained weights' best,
  // and the log keeps both validations: one run measures what the average is worth.
  double weight_average = 0;
  uint64_t seed = 1;
  // At each epoch's start (step 0) and after each batch (may be empty).
  std::function<void(const TrainProgress&)> progress;
  std::function<void(const EpochRecord&)> epoch_done;  // after each epoch (may be empty)
};

struct TrainResult {
  std::vector<EpochRecord> log;      // every epoch so far (resumed ones included)
  std::filesystem::path model;       // out/model.pt, the epoch with the lowest validation RMSE
  double best_val_rmse = 0;
  std::string device;                // where it trained
  std::string plot_error;            // why the learning curve could not be drawn, if so
  std::string validated_on = "val";  // the split validation (and the choice of model.pt) used
};

// The learning rate of 1-based `epoch` under options.lr_schedule:
//   step    lr for epochs 1..D, lr / lr_decay_factor after (D = lr_decay_epoch, -1: epochs / 2)
//   cosine  lr · (1 + cos(π (epoch − 1) / epochs)) / 2: lr at epoch 1, falling smoothly
//           towards 0 at the last epoch, so fewer epochs are spent at a rate whose gradient
//           noise holds the training error up (docs/sdn.md)
// Throws std::invalid_argument for an unknown schedule.
double LearningRateAt(const TrainOptions& options, int epoch);

// The folder holding the checkpoint out/state.json names (weights last.pt, their average
// last_average.pt, Adam's last_optim.pt): out/checkpoint-eNNNN, or out itself for runs written
// before checkpoint folders. Throws std::runtime_error naming state.json when it cannot be read
// or names a folder that is not there.
std::filesystem::path CheckpointDir(const std::filesystem::path& out);

// The checks of `options` that need no data (ranges, combinations, the model's shape, an earlier
// run in `out` without --resume or --overwrite), which Train makes first: the CLI makes them
// before its work and exits 2 for them, as for its own option errors (they exited 1, as a failed
// run; export-model exited 2 for an existing output).
// Throws std::invalid_argument naming the option and what it may be.
void ValidateTrainOptions(const TrainOptions& options);

// Trains (or resumes) and writes to options.out:
//   model.pt + model.json   best validation RMSE so far (what eval and sdn_node load)
//   checkpoint-eNNNN/{last.pt, last_optim.pt[, last_average.pt]}  the latest epoch (for --resume);
//   state.json its epoch, log and checkpoint folder (written after the folder is whole)
//   log.tsv                 one line per epoch; learning_curve.png (gnuplot)
// every file written atomically. Throws std::runtime_error on bad data or options.
TrainResult Train(const TrainOptions& options);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_TRAIN_H_
