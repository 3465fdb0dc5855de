// clothwind train: trains the SDN or a baseline of Table 1 (ResNet-18, Yang et al.'s LSTM) on a dataset
// (docs/dataset.md) with the seed's recipe; see docs/sdn.md.
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "learn/heap_reuse.h"
#include "learn/track_targets.h"
#include "learn/train.h"
#include "output_paths.h"
#include "progress_bar.h"
#include "resume_options.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct TrainArgs {
  learn::TrainOptions o;
  std::string data, out;
  int frames = 30;
  double still_floor = -1;  // -1: 1e-6 for the SDN, 0 for the baselines (which have no spectral layer)
};

VerbRegistrar registrar("train", [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<TrainArgs>();
  auto* sub = app.add_subcommand("train", "train the SDN or a ResNet-18 baseline (Table 1) on a dataset");
  learn::TrainOptions& o = args->o;
  sub->add_option("--model", o.model.arch,
                  "sdn (spectral layer + ResNet-18), resnet18 (frames as channels) or lstm (Yang et al.: "
                  "ResNet-18 per frame + LSTM)")
      ->check(CLI::IsMember({"sdn", "resnet18", "lstm"}))
      ->capture_default_str();
  sub->add_option("--frames", args->frames, "input frames N_t (Table 1: 1, 10, 20 for resnet18; 20, 30 for sdn)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  sub->add_option("--data", args->data, "dataset folder (index.json + examples); required unless --init-only");
  sub->add_option("--out", args->out, "run folder (model.pt/json, checkpoints, log.tsv, learning_curve.png)")
      ->required();
  sub->add_option("--epochs", o.epochs, "epochs (the seed: ~40)")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--batch", o.batch, "clips per batch (at least 2 to train: batch normalisation)")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--input-size", o.model.input_size, "input side [px] (224 as the seed, 112 on a CPU)")
      ->check(CLI::Range(16, 1024))
      ->capture_default_str();
  sub->add_option("--width", o.model.width, "ResNet-18 base width (64 as the original)")
      ->check(CLI::Range(1, 512))
      ->capture_default_str();
  CLI::Option* k = sub->add_option("--k", o.model.k, "SDN: spectral peaks per pixel")->check(CLI::Range(1, 64))->capture_default_str();
  sub->add_flag("--include-dc", o.model.include_dc,
                "SDN: the DC bin competes for the k peaks, signals not detrended (Algorithm 1 verbatim)");
  sub->add_option("--dft-size", o.model.dft_size,
                  "SDN: DFT length, the windowed signal zero-padded to it (0: N_t, Algorithm 1; 120 samples a "
                  "30-frame clip's spectrum every 0.21 Hz instead of 0.83)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  sub->add_flag("--local-peaks", o.model.local_peaks,
                "SDN: keep the k strongest local maxima of each pixel's periodogram, not the k strongest bins");
  sub->add_option("--dropout", o.model.dropout, "dropout probability on the pooled features (training only)")
      ->check(CLI::Range(0.0, 0.95))
      ->capture_default_str();
  sub->add_flag("--phase-steps", o.model.phase_steps,
                "SDN: add the strongest peak's phase step to the right and lower neighbour (cos, sin): a "
                "travelling wave's wavenumber");
  sub->add_option("--phase-step-far", o.model.phase_step_far,
                  "SDN with --phase-steps: also the phase step over this many pixels (0: none; a long wave's "
                  "wavenumber above one pixel's phase noise)")
      ->check(CLI::Range(0, 64))
      ->capture_default_str();
  sub->add_flag("--mode-shape", o.model.mode_shape,
                "SDN: add each pixel's amplitude at the clip's dominant frequency relative to the pixel that moves "
                "most (real, imaginary): the whole flag's wave at once, its wavelength as stripes");
  sub->add_option("--still-floor", args->still_floor,
                  "SDN: a pixel's selected bins at or below this times the clip's mean periodogram read no motion "
                  "(power and frequency 0) instead of the arbitrary frequencies of a flat spectrum; 0: off, as "
                  "models trained before the option [default: 1e-6 for sdn]")
      ->check(CLI::Range(0.0, 0.5));
  sub->add_option("--spectral-pool", o.model.spectral_pool,
                  "SDN: average-pool the spectral maps by this factor before the trunk (--input-size 128 "
                  "--spectral-pool 2: 128-px spectra, a 64-px trunk's cost)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  sub->add_flag_callback("--no-stem-pool", [args] { args->o.model.stem_pool = false; },
                "leave out the trunk's max pool after its stem: its stages see twice the resolution, at "
                "about four times their cost");
  sub->add_flag("--coord-maps", o.model.coord_maps,
                "give the trunk each pixel's column and row in (-1, 1) as two more channels (CoordConv): where "
                "in the frame the flag moves, which average pooling otherwise sees only through the padding");
  sub->add_flag("--flow", o.model.flow,
                "each frame's optical flow from the one before (DIS) as two more input channels: what "
                "moves, whatever the flag's design shows (docs/sdn.md)");
  sub->add_option("--flow-size", o.model.flow_size,
                  "with --flow: compute the flow on the crop resized to this side [px], then bring it to "
                  "--input-size (0: at --input-size)")
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--colour", o.model.colour,
                "colour frames (Y, Cr, Cb: three input channels) instead of grey ones: the edges between "
                "two colours of one grey (FlagSim's red and green) move too; not with --flow");
  sub->add_option("--head-hidden", o.model.head_hidden,
                  "ReLU units of a hidden layer before the wind output (0: a linear head, ResNet's)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  sub->add_option("--frame-channels", o.model.frame_channels,
                  "SDN: this many of the window's frames, evenly spaced, as more trunk channels beside the "
                  "spectral maps: where the cloth is at those instants, which the spectra drop (0: none)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  sub->add_flag("--mean-map", o.model.mean_map, "SDN: add the clip's per-pixel temporal mean (the pose) as a channel");
  sub->add_option("--threads", o.threads, "torch threads")->check(CLI::Range(1, 256))->capture_default_str();
  sub->add_option("--device", o.device, "cpu, cuda or auto (CUDA when libtorch finds one)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
      ->capture_default_str();
  CLI::Option* resume = sub->add_flag("--resume", o.resume, "continue the run in --out from its last epoch");
  // Not beside --resume: the pair resumed, --overwrite ignored without a word.
  sub->add_flag("--overwrite", o.overwrite,
                "start again in an --out that holds a run (without it, or --resume, such an --out is refused)")
      ->excludes(resume);
  sub->add_flag("--cache-frames", o.cache_frames,
                "keep every frame decoded at the input size in memory after its first read: the same samples, "
                "no rereading of a dataset larger than the page cache (needs --crop-scales 1; clips x frames x "
                "size^2 bytes of the training split, 4.1 GB for flagsim-e5 at 64 px)");
  sub->add_option("--aux-tracks", o.aux_tracks,
                  "weight of an auxiliary loss (0: off): a second head regresses each clip's grid of material "
                  "points (position and low-frequency motion, from the dataset's tracks.json: make-dataset "
                  "--tracks); the wind estimate does not read it")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--aux-phases", o.aux_phase_bins,
                  "with --aux-tracks: the auxiliary head also regresses each point's motion phase relative to a "
                  "fly corner's at DFT bins 1..N (0: none), the flag's travelling wave")
      ->check(CLI::Range(0, learn::kTrackBins))
      ->capture_default_str();
  sub->add_flag("--aux-world", o.aux_world,
                "with --aux-tracks: the auxiliary head also regresses the points' positions and motion in metres "
                "(tracks.json's \"world\": the cloth's shape whatever camera filmed it)");
  sub->add_flag("--point-maps", o.point_maps,
                "with --aux-tracks: the points' window-mean positions come from heat maps on the trunk's stage "
                "maps (a feature pyramid and a soft argmax) instead of the linear head on pooled features");
  sub->add_option("--weight-average", o.weight_average,
                  "decay of an exponential moving average of the weights, updated every step (0: off); until "
                  "step 9/(1-D)-10 (8990 for 0.999) a warm-up keeps it over the last ~1/9 of the steps; validation then reads the average, model.pt is its best epoch and "
                  "raw_model.pt the trained weights' best")
      ->check(CLI::Range(0.0, 0.9999999))
      ->capture_default_str();
  // Refused together at parsing (Train refuses them too): --init-only wrote the resumed run's last
  // weights over its best model.pt and called them untrained.
  sub->add_flag("--init-only", o.init_only, "write an initialised (untrained) model and stop (tests, smoke runs)")
      ->excludes(resume);
  sub->add_option("--lr", o.lr, "initial learning rate (Adam)")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--lr-schedule", o.lr_schedule,
                  "step (the seed's: divide by 10 once) or cosine (from --lr down to 0 over the epochs)")
      ->check(CLI::IsMember({"step", "cosine"}))
      ->capture_default_str();
  CLI::Option* lr_decay_epoch = sub->add_option("--lr-decay-epoch", o.lr_decay_epoch,
                  "step: epochs at the initial rate before dividing it by 10 (-1: half the epochs, 20 of 40 as the seed)")
      ->capture_default_str();
  sub->add_option("--crop-scales", o.crop_scales,
                  "training crop sides as fractions of the frame's shorter side, one drawn per clip "
                  "(the seed's multi-scale crop: 1,0.875,0.75,0.66; 1 keeps the whole frame as eval does)")
      ->delimiter(',')
      ->check(CLI::Range(1e-3, 1.0))
      ->capture_default_str();
  sub->add_flag_callback("--no-flip", [args] { args->o.flip = false; },
                         "train on each clip the way round it was filmed, without the seed's random horizontal flips "
                         "(FlagSim's cameras all stand on one side of the flag)");
  sub->add_option("--weight-decay", o.weight_decay, "Adam weight decay")->check(CLI::NonNegativeNumber)->capture_default_str();
  sub->add_option("--grad-clip", o.grad_clip, "max gradient norm (0: off; -1: the seed's, 10 for lstm and off otherwise)")
      ->check(CLI::Range(-1.0, 1e9))
      ->capture_default_str();
  // -1 wrapped to 2^64-1: one fixed seed, not the "random" it reads as.
  sub->add_option("--seed", o.seed, "seed of initialisation, data order and augmentation (0..2^64-1)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  return [args, lr_decay_epoch, k, sub]() {
    // First, so the checks below judge the run's own options (a cosine run resumed with
    // --lr-decay-epoch passed them against the default step schedule).
    if (args->o.resume) {
      const std::vector<std::string> filled = FillFromRunState(
          std::filesystem::path(args->out) / "state.json",
          [sub](const std::string& flag) { return sub->get_option(flag)->count() > 0; }, &args->o, &args->frames);
      std::string flags;
      for (const std::string& flag : filled) flags += " " + flag;
      if (!filled.empty()) std::cout << "resuming " << args->out << " with the run's own" << flags << " (its state.json)\n";
    }
    // k has a default, so ModelConfig cannot tell it given: a resnet18 or lstm sweep over --k
    // made identical runs, each recording its k.
    if (k->count() > 0 && args->o.model.arch != "sdn")
      throw UsageError("--k is the SDN's (spectral peaks per pixel); --model " + args->o.model.arch +
                                  " has no spectral layer");
    // The cosine schedule has no decay epoch: accepted, recorded in state.json and never used.
    if (lr_decay_epoch->count() > 0 && args->o.lr_schedule == "cosine")
      throw UsageError("--lr-decay-epoch is the step schedule's; --lr-schedule cosine decays over every epoch");
    // Every batch allocates and frees the same tensors: keep the freed memory instead of faulting
    // its pages in again (a training step 7 % faster at 64 px, 13 % at 96, on 2 cores).
    learn::KeepFreedHeapForReuse();
    learn::TrainOptions o = args->o;
    o.model.frames = args->frames;
    o.model.still_floor = args->still_floor >= 0 ? args->still_floor : o.model.arch == "sdn" ? 1e-6 : 0.0;
    o.still_floor_default = args->still_floor < 0;  // resumed, the run's own
    o.data = args->data;
    o.out = args->out;
    RefuseOutputInsideFolder("--out", o.out, o.data, "the dataset");
    RefuseUnwritableOutputFolder("--out", o.out);
    // The options' own checks, before any work, as a command-line error (exit 2, not 1).
    try {
      learn::ValidateTrainOptions(o);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    std::unique_ptr<ProgressBar> bar;
    int bar_epoch = 0;
    // The whole run's time left, from this process's mean epoch (the bar's ETA is the epoch's:
    // nothing said how long a 20-epoch run had to go). A resumed run's earlier epochs ran elsewhere.
    int epochs_timed = 0;
    double epoch_seconds = 0;
    auto run_left = [&](int epochs_left) {
      return epochs_timed > 0 && epochs_left > 0 ? FormatDuration(epochs_left * epoch_seconds / epochs_timed)
                                                 : std::string();
    };
    o.progress = [&](const learn::TrainProgress& p) {
      if (p.epoch != bar_epoch) {
        ProgressBar::Options b;
        b.label = "train epoch " + Num(p.epoch) + "/" + Num(p.epochs);
        const std::string left = run_left(p.epochs - p.epoch + 1);
        if (!left.empty()) b.label += " (run ~" + left + " left)";
        b.unit = "batches";
        b.rate_scale = o.batch;
        b.rate_unit = "clips/s";
        bar = std::make_unique<ProgressBar>(b);
        bar_epoch = p.epoch;
      }
      std::ostringstream note;
      if (p.step > 0) note << "loss " << std::setprecision(4) << p.loss;
      // Not "clips": with --weight-average each val clip is run twice (the model and its average).
      if (p.val_total > 0) note << ", validating " << p.val_done << "/" << p.val_total << " clip runs";
      bar->Update(p.step, p.steps, note.str());
    };
    o.epoch_done = [&](const learn::EpochRecord& e) {
      if (bar) bar->Finish();
      std::cout << std::fixed << std::setprecision(4) << "epoch " << e.epoch << "/" << o.epochs << "  lr " << e.lr
                << "  train loss " << e.train_loss << " rmse " << e.train_rmse << "  val loss " << e.val_loss
                << " rmse " << e.val_rmse << " acc@0.5 " << e.val_acc05;
      if (o.aux_tracks > 0) std::cout << "  aux loss " << e.train_aux_loss;
      if (o.weight_average > 0) std::cout << "  (trained weights: val rmse " << e.raw_val_rmse << ")";
      std::cout << "  " << std::setprecision(1) << e.seconds << " s";
      ++epochs_timed;
      epoch_seconds += e.seconds;
      const std::string left = run_left(o.epochs - e.epoch);
      if (!left.empty()) std::cout << "  (run: ~" << left << " left)";
      std::cout << std::endl;
    };
    // The run's folder, taken away again while still empty when training fails before writing
    // (a dataset it cannot read left an empty run folder; MadeFolders).
    const MadeFolders run_folders = MakeFoldersFor("--out", std::filesystem::path(o.out) / "state.json");
    const learn::TrainResult r = learn::Train(o);
    if (o.init_only) {
      std::cout << "initialised (untrained) model: " << r.model.string() << "\n";
      return 0;
    }
    std::cout << "best validation RMSE " << std::setprecision(4) << r.best_val_rmse << " m/s; model "
              << r.model.string() << " (trained on " << r.device << ")\n";
    if (r.validated_on != "val")
      std::cout << "note: validated on " << r.validated_on << ": the RMSE above is not a held-out score\n";
    if (!r.plot_error.empty()) std::cerr << "learning curve not drawn: " << r.plot_error << "\n";
    return 0;
  };
});

}  // namespace
}  // namespace clothwind::tools
