// clothwind make-dataset --kind flag|cloth --count N --out DIR: FlagSim / ClothSim datasets of
// simulated and rendered clips (docs/datasets.md), resumable, parallel, shardable.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "common/parse_pair.h"
#include "output_paths.h"
#include "data/dataset_generator.h"
#include "data/example_sampling.h"
#include "render/background.h"
#include "progress_bar.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

namespace fs = std::filesystem;

struct MakeDatasetArgs {
  data::DatasetOptions o;
  std::string kind = "flag";
  std::string shard = "0/1";
  std::string format = "jpg";
  double wind_min = -1, wind_max = -1;
  // FlagSim material priors (SamplingRanges); < 0: the default.
  double area_weight_spread = -1, bending_spread = -1, bending_jitter = -1;
  // Camera ranges "MIN:MAX" [m] and half-range [deg]; empty / < 0: Table 2's.
  std::string camera_height, camera_radius;
  double camera_angle = -1;
  bool reindex = false;
  bool no_contact_sheet = false;
  std::string backgrounds;  // folder of images
  std::string tracks;       // "COLSxROWS"
};

// "i/N" -> (i, N).
void ParseShard(const std::string& text, int* shard, int* shards) {
  const auto stoi = [](const std::string& t, size_t* n) { return std::stoi(t, n); };
  if (!ParsePair(text, '/', stoi, shard, shards))
    throw UsageError("--shard: expected i/N (e.g. 3/8), got '" + text + "'");
  if (*shards < 1 || *shard < 0 || *shard >= *shards)
    throw UsageError("--shard " + text + ": expected 0 <= i < N");
}

// "MIN:MAX" -> (min, max), for the option named `option`.
void ParseRange(const std::string& option, const std::string& text, double* lo, double* hi) {
  const auto stod = [](const std::string& t, size_t* n) { return std::stod(t, n); };
  if (!ParsePair(text, ':', stod, lo, hi))
    throw UsageError(option + ": expected MIN:MAX in metres (e.g. 5.1:6.1), got '" + text + "'");
}

int Run(MakeDatasetArgs& a) {
  data::DatasetOptions& o = a.o;
  RefuseUnwritableOutputFolder("--out", o.out);
  if (a.reindex) {
    ProgressBar::Options b;
    b.label = "make-dataset --reindex";
    b.unit = "labels";
    ProgressBar bar(b);
    const int64_t n = data::ReindexDataset(o.out, !a.no_contact_sheet,
                                           [&](int done, int total) { bar.Update(done, total); });
    bar.Finish();
    std::printf("make-dataset: %s/index.json rebuilt: %lld examples\n", o.out.c_str(), static_cast<long long>(n));
    return 0;
  }
  o.kind = render::SceneKindFromName(a.kind);
  ParseShard(a.shard, &o.shard, &o.shards);
  o.frame_ext = a.format == "jpeg" ? "jpg" : a.format;
  o.contact_sheet = !a.no_contact_sheet;
  if (!a.tracks.empty()) o.tracks = data::ParseTrackGrid("--tracks", a.tracks);
  // -1 (the default) is "not given"; anything else, NaN included, goes to the ranges to be checked
  // there (a NaN used to read as "not given", and the default was used without a word).
  const auto given = [](double v) { return v != -1; };
  // Each kind's own options: the other kind ran as if they were not given, and its header
  // recorded them (a ClothSim header said area-weight spread 50 of a dataset drawn without one).
  if (o.kind == render::SceneKind::kCloth) {
    for (const auto& [name, value] : {std::pair<const char*, double>{"--area-weight-spread", a.area_weight_spread},
                                      {"--bending-spread", a.bending_spread},
                                      {"--bending-jitter", a.bending_jitter}})
      if (given(value))
        throw UsageError(std::string(name) + " is FlagSim's (--kind flag); ClothSim draws its fabrics "
                                    "from --materials");
  } else if (!o.materials_dir.empty()) {
    throw UsageError("--materials is ClothSim's (--kind cloth); FlagSim's material is the scene's");
  }
  if (given(a.wind_min) || given(a.wind_max) || given(a.area_weight_spread) || given(a.bending_spread) ||
      given(a.bending_jitter) || !a.camera_height.empty() || !a.camera_radius.empty() || given(a.camera_angle)) {
    data::SamplingRanges r = data::DefaultRanges(o.kind);
    if (given(a.wind_min)) r.wind_min = a.wind_min;
    if (given(a.wind_max)) r.wind_max = a.wind_max;
    if (given(a.area_weight_spread)) r.area_weight_factor = a.area_weight_spread;
    if (given(a.bending_spread)) r.bending_factor = a.bending_spread;
    if (given(a.bending_jitter)) r.bending_jitter = a.bending_jitter;
    if (!a.camera_height.empty())
      ParseRange("--camera-height", a.camera_height, &r.camera.height_min, &r.camera.height_max);
    if (!a.camera_radius.empty())
      ParseRange("--camera-radius", a.camera_radius, &r.camera.radius_min, &r.camera.radius_max);
    if (given(a.camera_angle)) r.camera.angle_max_deg = a.camera_angle;
    // The command line's ranges, checked as options (status 2) before the line saying what the run
    // makes: they failed after it, as a failed run.
    try {
      data::ValidateRanges(r);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
    o.ranges = r;
  }
  // The renderer's own listing (any case, .bmp too, files only): this verb's copy refused .JPG.
  if (!a.backgrounds.empty()) {
    // Not the photos' folder itself: the dataset's contact sheet became a backdrop of the next
    // dataset made from it, and a resume was refused for photos that had changed. (The photos are
    // listed from its top level only, so a dataset in a subfolder of it is harmless.)
    if (IsAtOrInside(o.out, a.backgrounds) && IsAtOrInside(a.backgrounds, o.out))
      throw UsageError("--out " + o.out + " is the --backgrounds folder; its contact sheet would become a "
                       "background photo: write the dataset elsewhere (a subfolder will do)");
    o.background_images = render::ListBackgroundImages(a.backgrounds);
  }

  // Before the line that says what it will make: "--views must be in 1..64" came after it, and
  // exited 1 as a failed run.
  try {
    data::ValidateDatasetOptions(o);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  ProgressBar::Options bar_options;
  bar_options.label = "make-dataset";
  bar_options.unit = "simulations";
  // --add-tracks renders no clip: its pace is in simulations replayed.
  bar_options.rate_scale = o.add_tracks ? 60.0 : 60.0 * o.views;
  bar_options.rate_unit = o.add_tracks ? "simulations/min" : "clips/min";
  ProgressBar bar(bar_options);
  std::fprintf(stderr, "make-dataset: %s, %lld simulations x %d views, seed %llu, shard %d/%d, %s\n",
               a.kind.c_str(), static_cast<long long>(o.count), o.views,
               static_cast<unsigned long long>(o.seed), o.shard, o.shards, o.out.c_str());
  // The index is rebuilt from every label at the end (tens of seconds for 20,000 examples): a bar
  // of its own, made at its first label, after the simulations' bar has ended its line.
  std::unique_ptr<ProgressBar> index_bar;
  const data::DatasetSummary s = data::GenerateDataset(
      o, [&](const data::DatasetProgress& p) { bar.Update(p.done, p.total, p.last); },
      [&](int done, int total) {
        if (!index_bar) {
          bar.Finish();
          ProgressBar::Options b;
          b.label = "make-dataset index";
          b.unit = "labels";
          index_bar = std::make_unique<ProgressBar>(b);
        }
        index_bar->Update(done, total);
      });
  bar.Finish();
  if (index_bar) index_bar->Finish();

  const double busy = s.simulate_seconds + s.render_seconds + s.write_seconds;
  std::printf("make-dataset: %s\n", o.out.c_str());
  std::printf("  shard %d/%d: %lld simulations assigned, %lld already complete, %lld run now "
              "(%lld failed), %lld example folders written\n",
              o.shard, o.shards, static_cast<long long>(s.assigned), static_cast<long long>(s.skipped),
              static_cast<long long>(s.simulated), static_cast<long long>(s.failed),
              static_cast<long long>(s.examples_written));
  std::printf("  wall %.1f s on %d jobs; worker time: simulate %.1f s, render %.1f s, write %.1f s\n",
              s.wall_seconds, s.jobs, s.simulate_seconds, s.render_seconds, s.write_seconds);
  if (s.examples_written > 0 && o.add_tracks) {
    std::printf("  per example: %.2f s of worker time (a simulation's replay shared by its views)\n",
                busy / s.examples_written);
  } else if (s.examples_written > 0) {
    std::printf("  per example: %.2f s of worker time (render %.1f ms/frame); %.1f clips/min overall\n",
                busy / s.examples_written, 1e3 * s.render_seconds / (s.examples_written * o.frames),
                60.0 * s.examples_written / s.wall_seconds);
  }
  std::printf("  index: %s (%lld examples in the folder)\n", s.index_path.c_str(),
              static_cast<long long>(s.examples_in_index));
  if (s.examples_without_tracks > 0)
    std::printf("  %lld example(s) still without tracks.json: the index records no tracks grid until a later "
                "--add-tracks run gives them theirs\n",
                static_cast<long long>(s.examples_without_tracks));
  if (!s.contact_sheet_path.empty()) std::printf("  contact sheet: %s\n", s.contact_sheet_path.c_str());
  for (const auto& e : s.errors) std::fprintf(stderr, "make-dataset: FAILED %s\n", e.c_str());
  return s.failed > 0 ? 1 : 0;
}

const VerbRegistrar kRegistrar{"make-dataset", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<MakeDatasetArgs>();
  auto* sub = app.add_subcommand("make-dataset",
                                 "FlagSim/ClothSim dataset: simulate, render clips from several views, "
                                 "label; resumable, parallel, shardable");
  sub->add_option("--kind", a->kind, "flag (FlagSim) or cloth (ClothSim)")
      ->check(CLI::IsMember({"flag", "cloth"}))->capture_default_str();
  sub->add_option("--count", a->o.count,
                  "number of simulations, at most 1000000 (examples = count x views); required unless --reindex");
  sub->add_option("--out", a->o.out, "dataset folder")->required();
  sub->add_option("--seed", a->o.seed, "global seed (0..2^64-1)")->check(CLI::NonNegativeNumber)->capture_default_str();
  sub->add_option("--shard", a->shard, "i/N: do the simulations with index % N == i")->capture_default_str();
  sub->add_option("--jobs", a->o.jobs, "parallel simulations (0: all cores)")->capture_default_str();
  sub->add_option("--views", a->o.views, "camera poses rendered per simulation (1..64)")->capture_default_str();
  sub->add_option("--materials", a->o.materials_dir,
                  "ClothSim fabrics folder (default: $CLOTHWIND_SHARED_DIR/arcsim/materials, else config/materials; "
                  "refused with --kind flag)");
  sub->add_option("--scene", a->o.scene, "scene file (default: config/scenes/<kind>.json)");
  sub->add_option("--max-edge", a->o.max_edge, "mesh resolution [m] (0: the scene's default)")->capture_default_str();
  sub->add_option("--warmup", a->o.warmup,
                  "simulated time before the first kept frame [s] (0..3600, a whole number of frames: a multiple of 1/fps)")
      ->capture_default_str();
  sub->add_option("--frames", a->o.frames, "frames per example (>= 1)")->capture_default_str();
  sub->add_option("--samples", a->o.samples, "anti-aliasing samples per pixel (0: zeta's default, 4)")
      ->capture_default_str();
  sub->add_option("--size", a->o.size, "frame width = height [px] (16..4096)")->capture_default_str();
  sub->add_option("--format", a->format,
                  "frame format (pgm: 8-bit grey as the SDN reads it, lossless, readable without an image codec)")
      ->check(CLI::IsMember({"jpg", "jpeg", "png", "pgm"}))
      ->capture_default_str();
  CLI::Option* quality = sub->add_option("--jpeg-quality", a->o.jpeg_quality, "JPEG quality 1..100")->capture_default_str();
  sub->add_option("--wind-min", a->wind_min, "lowest wind speed [m/s] (default: flag 0, cloth 0)")
      ->check(CLI::Range(0.0, 100.0));
  sub->add_option("--wind-max", a->wind_max, "highest wind speed [m/s] (default: flag 10, cloth 5)")
      ->check(CLI::Range(0.0, 100.0));
  // Why a narrow area weight: the wind's pressure balances the flag's weight, so the droop shows
  // rho v^2 / (w g); a flag of unknown weight in [w/2, 2w] leaves v uncertain by a factor of 2
  // (docs/datasets.md). A deployed flag can be weighed; its bending stiffness cannot easily.
  sub->add_option("--area-weight-spread", a->area_weight_spread,
                  "FlagSim: area weight = base x f, f log-uniform in [1/F, F] (default 2; 1 = the scene's)")
      ->check(CLI::Range(1.0, 100.0));
  sub->add_option("--bending-spread", a->bending_spread,
                  "FlagSim: overall bending stiffness factor log-uniform in [1/G, G] (default 4)")
      ->check(CLI::Range(1.0, 100.0));
  sub->add_option("--bending-jitter", a->bending_jitter,
                  "FlagSim: per-entry bending factor log-uniform in [1/H, H] (default 1.25)")
      ->check(CLI::Range(1.0, 100.0));
  // Why: Table 2's cameras look up at the flag from 0.2-3 m; a site's own camera (say on a roof,
  // level with the flag) is better served by a dataset drawn around where it stands.
  sub->add_option("--camera-height", a->camera_height,
                  "camera height above the ground MIN:MAX [m] (default: flag 0.2:3, cloth 0.5:2)");
  sub->add_option("--camera-radius", a->camera_radius,
                  "camera's horizontal distance from the mesh's centre MIN:MAX [m] (default: flag 4:6, cloth 1:2.5)");
  sub->add_option("--camera-angle", a->camera_angle,
                  "camera angle off side-on, +-DEG (default: flag 15, cloth 5)")
      ->check(CLI::Range(0.0, 89.9));
  sub->add_option("--val", a->o.val_fraction, "fraction of simulations in the val split (val + test <= 1)")->capture_default_str();
  sub->add_option("--test", a->o.test_fraction, "fraction of simulations in the test split (val + test <= 1)")->capture_default_str();
  sub->add_option("--backgrounds", a->backgrounds,
                  "folder of background images, .jpg .jpeg .png .bmp in any case (default: procedural)");
  sub->add_flag("--reindex", a->reindex,
                "only rebuild index.json and the contact sheet from the example folders (merge shards)");
  sub->add_flag("--no-contact-sheet", a->no_contact_sheet, "skip contact_sheet.png");
  sub->add_option("--tracks", a->tracks,
                  "also write each example's tracks.json: where a COLSxROWS grid of the cloth's material "
                  "points is in each frame (e.g. 8x6; training's --aux-tracks reads them)");
  sub->add_flag("--add-tracks", a->o.add_tracks,
                "render nothing: give the examples already in --out their tracks.json, or tracks.json with the points' "
                "positions where theirs has none (needs --tracks and "
                "the options the dataset was made with; each replayed simulation is checked against "
                "its stored frames)");
  sub->add_option("--split", a->o.split,
                  "only this split's simulations, as the whole dataset has them (test: to evaluate a model "
                  "without making its training data; with --add-tracks, train: what --aux-tracks reads)")
      ->check(CLI::IsMember({"train", "val", "test"}));
  return [a, sub, quality] {
    // Lossless frames take no quality: it was accepted, unused, and written into the header.
    if (quality->count() > 0 && (a->format == "png" || a->format == "pgm"))
      throw UsageError("--jpeg-quality is for JPEG frames; --format " + a->format + " is lossless");
    // --reindex reads the header and labels as they are: any other option was accepted and
    // ignored (--count 99 --kind cloth --tracks 9x9 rebuilt the same index under the old header).
    if (a->reindex) {
      for (const CLI::Option* option : sub->get_options()) {
        const std::string name = option->get_name();
        if (option->count() > 0 && name != "--out" && name != "--reindex" && name != "--no-contact-sheet")
          throw UsageError(name + " is not used by --reindex, which rebuilds the index under the header "
                                      "the dataset was made with (give only --out and --no-contact-sheet)");
      }
    }
    if (!a->reindex && sub->get_option("--count")->count() == 0) throw UsageError("--count N (N >= 1) is required");
    if (!a->reindex && a->o.count <= 0)
      throw UsageError("--count must be >= 1, got " + Num(a->o.count));
    return Run(*a);
  };
}};

}  // namespace
}  // namespace clothwind::tools
