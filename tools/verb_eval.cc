// clothwind eval: a trained wind network over a dataset split in Table 1's terms (RMSE,
// Acc@0.5), a predicted-vs-true plot and optionally the figures as JSON; see docs/sdn.md.
#include <iostream>
#include <memory>

#include "learn/evaluate.h"
#include "learn/model_config.h"
#include "learn/track_head_eval.h"
#include "learn/view_breakdown.h"
#include "progress_bar.h"
#include "dataset_outputs.h"
#include "output_paths.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct EvalArgs {
  std::string model, data, split = "test", json, plot, track_head_rows;
  int threads = 2, batch = 8, windows = 1, track_head_window = 0;
  std::string device = "auto";
  bool mirror = false;
  bool mirror_clips = false;
  std::string flag_flies = "right";
  std::string fly_judge;
  bool by_view = false;
  bool track_head = false;
};

VerbRegistrar registrar("eval", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<EvalArgs>();
  auto* sub = app.add_subcommand("eval", "evaluate a trained wind network (Table 1: RMSE, Acc@0.5)");
  sub->add_option("--model", a->model, "model.pt of a training run (model.json beside it)")->required();
  sub->add_option("--data", a->data, "dataset folder")->required();
  sub->add_option("--split", a->split, "test, val, train or all")
      ->check(CLI::IsMember({"test", "val", "train", "all"}))
      ->capture_default_str();
  sub->add_option("--json", a->json, "write {\"rmse\", \"acc05\", \"count\", ...} to this file");
  sub->add_option("--plot", a->plot, "predicted-vs-true PNG, its folder made if missing (default: <model folder>/eval_<split>.png, with a suffix such as _w3 for a reading "
                  "other than Table 1's); its data (.dat, every clip's truth, prediction and std) and gnuplot script "
                  "(.gp) are written beside it");
  sub->add_option("--threads", a->threads, "torch threads")->check(CLI::Range(1, 256))->capture_default_str();
  sub->add_option("--batch", a->batch, "clips per forward pass")->check(CLI::PositiveNumber)->capture_default_str();
  sub->add_option("--windows", a->windows,
                  "average this many evenly spaced frame windows per clip (1: the centred one, Table 1; a clip "
                  "with fewer distinct ones is read at each once, and the table and JSON say so)")
      ->check(CLI::Range(1, 1000))  // a huge count hung (windows rebuilt per window)
      ->capture_default_str();
  sub->add_flag("--mirror", a->mirror,
               "also predict each window's mirror image (horizontal flip) and average the two (Table 1: off)");
  sub->add_flag("--mirror-clips", a->mirror_clips,
               "mirror every clip first, as if its flag flew left (FlagSim's all fly right): how the model reads "
               "flags flying the other way");
  sub->add_option("--flag-flies", a->flag_flies,
                  "turn each clip round before the model reads it: right (as it comes), left (mirror every clip) "
                  "or auto (mirror those the fly judge, or without one their motion, says fly left; the node's "
                  "default for a model trained with --no-flip)")
      ->check(CLI::IsMember({"right", "left", "auto"}))
      ->capture_default_str();
  sub->add_option("--fly-judge", a->fly_judge,
                  "with --flag-flies auto: the judge that decides (train-fly-judge's file; default: fly_judge.pt "
                  "beside the model when there is one, else the clip's motion cues)");
  sub->add_flag("--by-view", a->by_view,
               "also break the errors down by the clips' views (camera elevation, angle, distance; texture), "
               "read from each simulated clip's label.json");
  sub->add_flag("--track-head", a->track_head,
               "also report how well the run's auxiliary track head (--aux-tracks) knows the points: window-mean "
               "positions in pixels of the input, log amplitudes per bin (a run's model.pt; export drops the head)");
  sub->add_option("--track-head-rows", a->track_head_rows,
                  "with --track-head: write each clip's predicted and true track targets to this file (TSV)");
  sub->add_option("--track-head-window", a->track_head_window,
                  "with --track-head: read the head over this many centred frames, a multiple of the model's, "
                  "its outputs averaged over the consecutive inputs (0: the model's own frames; 30 with a "
                  "--frames 1 network: the window-mean positions a per-frame tracker gives a 30-frame window)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  sub->add_option("--device", a->device,
                  "cpu, cuda or auto (CUDA when there is one; there in full float32, TF32 off, as on the CPU)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}))
      ->capture_default_str();
  return [a]() {
    if (!a->track_head_rows.empty() && !a->track_head) {
      std::cerr << "clothwind eval: --track-head-rows needs --track-head\n";
      return 2;
    }
    if (a->track_head_window != 0 && !a->track_head) {  // accepted and ignored
      std::cerr << "clothwind eval: --track-head-window needs --track-head\n";
      return 2;
    }
    if (!a->fly_judge.empty() && a->flag_flies != "auto") {
      std::cerr << "clothwind eval: --fly-judge decides only with --flag-flies auto\n";
      return 2;
    }
    if (a->track_head && (a->mirror_clips || a->flag_flies != "right")) {
      // The head's targets are the points of the clip as filmed.
      std::cerr << "clothwind eval: --track-head reads clips as filmed, not with --mirror-clips or --flag-flies "
                << a->flag_flies << "\n";
      return 2;
    }
    const std::vector<std::filesystem::path> inputs = {a->model, learn::ConfigPathFor(a->model),
                                                        std::filesystem::path(a->data) / "index.json", a->fly_judge};
    RefuseOutputOverInput("--json", a->json, inputs);
    RefuseOutputOverInput("--plot", a->plot, inputs);
    const std::filesystem::path plot =
        a->plot.empty() ? std::filesystem::path(a->model).parent_path() /
                              ("eval_" + a->split +
                               learn::EvalProtocolSuffix(a->windows, a->mirror, a->mirror_clips, a->flag_flies) + ".png")
                        : std::filesystem::path(a->plot);
    // The plot and its gnuplot data file replaced the JSON written just before them.
    for (const std::filesystem::path& drawn : {plot, std::filesystem::path(plot.string() + ".dat")})
      if (!a->json.empty() && SameFile(a->json, drawn))
        throw UsageError("--json " + a->json + " is where the plot goes (" + drawn.string() +
                                    "); write one of them elsewhere");
    // Nor on a clip's label or frames (only index.json was guarded).
    RefuseOutputInsideExamples("--json", a->json, a->data);
    RefuseOutputInsideExamples("--plot", plot, a->data);
    RefuseUnwritableOutput("--json", a->json);
    RefuseUnwritableOutput("--plot", a->plot);
    // gnuplot draws a PNG whatever the name: `--plot p.txt` wrote one named .txt.
    if (!a->plot.empty() && std::filesystem::path(a->plot).extension() != ".png")
      throw UsageError("--plot " + a->plot + ": expected a file name ending in .png (the plot is a PNG)");
    if (a->track_head) {
      // Before the evaluation, which ran whole and then lost its results to a model without a head,
      // a window of the wrong length or a rows file over the model's configuration.
      RefuseOutputOverInput("--track-head-rows", a->track_head_rows, inputs);
      for (const std::string& other : {a->json, plot.string()})
        if (!a->track_head_rows.empty() && !other.empty() && SameFile(a->track_head_rows, other))
          throw UsageError("--track-head-rows " + a->track_head_rows + " is where another result goes (" +
                                      other + "); write one of them elsewhere");
      RefuseOutputInsideExamples("--track-head-rows", a->track_head_rows, a->data);
      RefuseUnwritableOutput("--track-head-rows", a->track_head_rows);
      learn::CheckTrackHead(a->model, a->track_head_window);
    }
    // Held to the end: a folder still empty then (an evaluation that failed, a plot not drawn) is
    // taken away again; one a result was written into stays.
    const MadeFolders json_folders = MakeFoldersFor("--json", a->json);
    // The default plot's folder is the model's: made, it would outlive a misspelt --model.
    const MadeFolders plot_folders = a->plot.empty() ? MadeFolders() : MakeFoldersFor("--plot", plot);
    const MadeFolders rows_folders = a->track_head ? MakeFoldersFor("--track-head-rows", a->track_head_rows)
                                                   : MadeFolders();
    ProgressBar::Options b;
    b.label = "eval";
    b.unit = "clips";
    ProgressBar bar(b);
    const learn::EvalResult r = learn::Evaluate(a->model, a->data, a->split, a->threads, a->device, a->batch,
                                                a->windows, a->mirror, a->mirror_clips,
                                                learn::FlagFliesFromName(a->flag_flies, "--flag-flies"),
                                                [&](int done, int total) { bar.Update(done, total); }, a->fly_judge);
    bar.Finish();
    std::cout << learn::EvalTable(r);
    nlohmann::json json = learn::EvalJson(r);
    // A clip without a view (a real one) must not cost the evaluation: the figures, plot and JSON
    // are still written, and the run then fails saying why the breakdown is missing.
    std::string by_view_error;
    if (a->by_view) {
      try {
        const learn::ViewBreakdown breakdown = learn::BreakDownByView(r);
        std::cout << learn::ViewBreakdownTable(breakdown);
        json["by_view"] = learn::ViewBreakdownJson(breakdown);
      } catch (const std::exception& e) {
        by_view_error = e.what();
      }
    }
    // The evaluation's figures are kept whatever the track head does after them.
    if (!a->json.empty() && a->track_head) {
      RemakeFolderFor(a->json);
      learn::WriteFileAtomically(a->json, json.dump(2) + "\n");
    }
    if (a->track_head) {
      ProgressBar::Options h = b;
      h.label = "track head";
      ProgressBar head_bar(h);
      const learn::TrackHeadReport head = learn::EvaluateTrackHead(
          a->model, a->data, a->split, a->threads, a->batch, [&](int done, int total) { head_bar.Update(done, total); },
          a->track_head_window);
      head_bar.Finish();
      std::cout << learn::TrackHeadTable(head);
      json["track_head"] = {{"window", head.window},
                            {"position_rmse_x_px", head.position_rmse_x},
                            {"position_rmse_y_px", head.position_rmse_y},
                            {"position_r2", head.position_r2},
                            {"amplitude_rmse", head.amplitude_rmse},
                            {"amplitude_r2", head.amplitude_r2},
                            {"standardised_mse", head.standardised_mse}};
      if (!a->track_head_rows.empty()) {
        RemakeFolderFor(a->track_head_rows);
        learn::WriteTrackHeadRows(head, a->track_head_rows);
        std::cout << "track head rows: " << a->track_head_rows << "\n";
      }
    }
    // An earlier run's plot goes before this run's figures are written: left, a run stopped while
    // gnuplot drew (or whose plot failed) left the old picture beside the new figures.
    {
      std::error_code ec;
      std::filesystem::remove(plot, ec);
    }
    // The figures first: a plot that cannot be written (a read-only model folder) costs only itself.
    if (!a->json.empty()) {
      RemakeFolderFor(a->json);
      learn::WriteFileAtomically(a->json, json.dump(2) + "\n");
      std::cout << "json: " << a->json << "\n";
    }
    std::string error;
    bool plot_failed = false;
    if (!a->plot.empty()) RemakeFolderFor(plot);  // the default's is the model's, not made
    if (learn::PlotPredictions(r, plot, &error)) {
      std::cout << "plot: " << plot.string() << "\n";
    } else {
      // The default goes beside the model, which an install's models folder does not take.
      std::cerr << "plot not drawn: " << error << (a->plot.empty() ? " (--plot PNG draws it elsewhere)" : "") << "\n";
      plot_failed = !a->plot.empty();  // the default plot is a courtesy; an asked-for one is a result
    }
    if (!by_view_error.empty()) {
      std::cerr << "clothwind eval: --by-view: " << by_view_error << "\n";
      return 1;
    }
    return plot_failed ? 1 : 0;
  };
});

}  // namespace
}  // namespace clothwind::tools
