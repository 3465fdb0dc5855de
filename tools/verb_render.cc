// clothwind render INPUT --out DIR: renders a cloth animation as 25 fps frames (300x300 JPEG or
// PNG by default) with the datasets' camera, light and scene sampling ζ (from --seed or a JSON
// file), so any simulator's cloth renders the same way. INPUT is our binary trajectory
// (.cwtraj, or a `clothwind simulate` folder holding trajectory.cwtraj) or a folder of
// ArcSim-style frame OBJs (0000_00.obj, 0001_00.obj, ...; --obj prefers them).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/atomic_file.h"
#include "closest_name.h"
#include "common/json_file.h"
#include "data/cloth_animation.h"
#include "output_paths.h"
#include "progress_bar.h"
#include "stale_frames.h"
#include "render/render_params.h"
#include "render/renderer.h"
#include "render/sensor_model.h"
#include "sim/trajectory_io.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

namespace fs = std::filesystem;

struct RenderArgs {
  std::string input;
  std::string out;
  std::string kind = "flag";
  uint64_t seed = 1;
  std::string zeta;        // JSON file (a ζ object, or a label.json with "zeta")
  bool keep_zeta = false;  // render --zeta as given even when its mesh size is not the cloth's
  std::string backgrounds; // folder a relative background_image of --zeta is found in
  std::string format = "jpg";
  int jpeg_quality = 95;
  double start = 0.0;      // [s] into the animation
  int count = 0;           // frames; 0 = to the end
  double fps = 25.0;
  double frame_time = 0.04;  // of an OBJ sequence [s]
  int cloth = 0;
  bool obj = false;
  bool frame_time_given = false, cloth_given = false;  // on the command line (for LoadInput's refusals)
  int samples = 0;
  int threads = 0;
};

render::RenderParams LoadZeta(const std::string& path) {
  nlohmann::json j = ReadJsonFile(path, "--zeta");
  if (j.contains("zeta")) j = j["zeta"];  // a dataset example's label.json
  // Keys zeta does not have (a misspelt "camera_hieght"), with the one each was likely meant to be:
  // ignored without a word, and beside a missing key the likely cause of its absence.
  render::RenderParams defaults;
  defaults.has_look_at = true;  // the one optional key
  std::vector<std::string> names;
  const nlohmann::json known = render::ToJson(defaults);  // held: items() of a temporary dangles
  for (const auto& [key, value] : known.items()) names.push_back(key);
  std::string unknown;
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      if (std::find(names.begin(), names.end(), key) != names.end()) continue;
      const std::string meant = ClosestName(key, names);
      unknown += (unknown.empty() ? "" : "; ") + ("key '" + key + "' is not a render parameter") +
                 (meant.empty() ? "" : " (did you mean " + meant + "?)");
    }
  }
  render::RenderParams p;
  try {
    p = render::RenderParamsFromJson(j);
  } catch (const std::exception& e) {
    throw std::runtime_error("--zeta " + path + ": " + e.what() + (unknown.empty() ? "" : "; " + unknown));
  }
  if (!unknown.empty()) std::cerr << "warning: --zeta " << path << ": " << unknown << " (ignored)\n";
  return p;
}

// The animation of a trajectory file, its errors naming the file (an animation's own checks,
// texture coordinates without extent, named none).
data::ClothAnimation AnimationOfTrajectory(const fs::path& file) {
  const sim::Trajectory t = sim::ReadTrajectory(file.string());
  try {
    return data::AnimationFromTrajectory(t);
  } catch (const std::exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
}

// Options that do not apply to the input found are refused, not ignored: --cloth 3 on a
// trajectory file rendered its one cloth, --frame-time beside a trajectory (which has its own
// times) changed nothing.
data::ClothAnimation LoadInput(const RenderArgs& a, std::string* what) {
  const fs::path in(a.input);
  if (fs::is_regular_file(in)) {
    for (const auto& [given, option] : {std::pair{a.cloth_given, "--cloth"}, std::pair{a.obj, "--obj"},
                                        std::pair{a.frame_time_given, "--frame-time"}})
      if (given)
        throw UsageError(std::string(option) + " is for a simulation folder; " + a.input +
                                    " is a trajectory file (one cloth, its own frame times)");
    *what = "trajectory " + in.string();
    return AnimationOfTrajectory(in);
  }
  if (!fs::is_directory(in))
    throw std::runtime_error(a.input + (fs::exists(in) ? ": not a file or folder (a pipe or a device), expected a "
                                                         ".cwtraj file or a simulation folder"
                                                       : ": no such file or folder"));
  const fs::path traj = in / (a.cloth == 0 ? std::string("trajectory.cwtraj")
                                            : "trajectory_" + Num(a.cloth) + ".cwtraj");
  if (!a.obj && fs::exists(traj)) {
    if (a.frame_time_given)
      throw UsageError("--frame-time is for OBJ frames; " + traj.string() +
                                  " has its own frame times (give --obj to render the OBJ frames)");
    *what = "trajectory " + traj.string();
    return AnimationOfTrajectory(traj);
  }
  // A simulate folder (its trajectory there) without summary.json, which simulate writes last: a
  // run stopped while it wrote its OBJs, whose sequence ends early (5 s of a 20 s run rendered,
  // exit 0, where the trajectory holds all 20).
  if (fs::exists(traj) && !fs::exists(in / "summary.json"))
    throw std::runtime_error("OBJ frames in " + in.string() + ": simulate did not finish there (no summary.json), so "
                             "its OBJ frames may stop short; render " + traj.string() + " without --obj, or simulate "
                             "again");
  *what = "OBJ frames in " + in.string();
  return data::ReadObjSequence(in.string(), a.cloth, a.frame_time);
}

// The pole, rod and camera aim follow ζ's mesh_width and mesh_aspect_ratio, so a cloth of
// another size (a custom scene or OBJ) flew beside its pole, the camera aimed past it, silently.
// A sampled ζ (--seed) takes the cloth's rest size; a given one (--zeta) must fit it, unless
// --keep-zeta (a label's ζ of a dataset made with another scene: its frames as they were made).
// A size within 5 % keeps ζ as it is: frames of the usual meshes stay what they were.
// The rest size is the material space's extent (exact); measured from the first frame only
// when unknown: a flag flying at 30 m/s after a warm-up measured 3.18 m for its 3 m, and --seed
// rewrote its ζ.
void FitMeshSize(const data::ClothAnimation& anim, const RenderArgs& a, render::RenderParams* zeta) {
  Eigen::Vector2d size = anim.rest_size;
  if (!(size.minCoeff() > 0)) {
    const data::ClothFrame first = data::FrameAt(anim, 0.0);
    size = render::MeasureClothSize(first.V, first.F, first.UV);
  }
  const std::string why = render::MeshSizeMismatch(*zeta, size);
  if (why.empty()) return;
  if (!a.zeta.empty() && a.keep_zeta) {
    std::fprintf(stderr, "render: --keep-zeta: %s; rendered with zeta as given\n", why.c_str());
    return;
  }
  if (!a.zeta.empty())
    throw UsageError("--zeta " + a.zeta + ": " + why +
                                " (render it with --seed to fit zeta to it, or --keep-zeta to render it as given)");
  render::SetMeshSize(size, zeta);
  std::fprintf(stderr, "render: the cloth measures %.4g x %.4g m; zeta's mesh_width and mesh_aspect_ratio follow it\n",
               size.x(), size.y());
  render::ValidateRenderParams(*zeta);
}

int Run(const RenderArgs& a) {
  RefuseUnwritableOutputFolder("--out", a.out);
  // --out's zeta.json goes before the first frame and comes back after the last (below): read as
  // --zeta, a run stopped half way lost the frames' only record of how they were made.
  if (!a.zeta.empty() && SameFile(a.zeta, fs::path(a.out) / "zeta.json"))
    throw UsageError("--zeta " + a.zeta + " is --out's own zeta.json, which render removes until its frames "
                                "are whole (a run stopped half way would lose it): copy it elsewhere first, or render "
                                "into another --out");
  render::RenderParams zeta = a.zeta.empty()
                                  ? render::SampleRenderParams(render::SceneKindFromName(a.kind), a.seed)
                                  : LoadZeta(a.zeta);
  // A dataset example's label names its background photo by file name alone (labels are the same
  // on every machine); the folder it is in comes from here.
  // Without --backgrounds it was looked up in the current folder: "no such file" naming no option,
  // or, where a photo of that name happened to be, another photo rendered without a word.
  // Made absolute, so the zeta.json written below renders the same photo from any folder.
  const std::filesystem::path photo = zeta.background_image;
  // A path with a folder (as an older render wrote it) is taken from the current folder.
  if (!photo.empty() && photo.is_relative()) {
    if (a.backgrounds.empty() && !photo.has_parent_path())
      throw UsageError("--zeta " + a.zeta + " names its background photo '" + zeta.background_image +
                                  "' by file name: pass --backgrounds DIR, the folder make-dataset was given");
    zeta.background_image =
        std::filesystem::absolute(std::filesystem::path(a.backgrounds) / photo).lexically_normal().string();
  }
  if (a.samples > 0) zeta.samples = a.samples;
  zeta.fps = a.fps;
  render::ValidateRenderParams(zeta);
  if (a.format != "jpg" && a.format != "png")
    throw UsageError("--format: expected jpg (or jpeg) or png, got '" + a.format + "'");
  std::string what;
  const data::ClothAnimation anim = LoadInput(a, &what);
  // Errors about what the input holds name it: "render params: field 'mesh_width' is 3e+38"
  // and "SetCloth: vertex 1 has V coordinate x = 1e+38" named no file.
  try {
    FitMeshSize(anim, a, &zeta);
  } catch (const std::exception& e) {
    throw std::runtime_error(what + ": " + e.what());
  }
  // NaN passed a range check written as (start < 0 || start > duration), and a frame count
  // computed from it or from a huge rate overflowed int: nothing rendered, the earlier run's
  // frames deleted, exit 0.
  if (!(a.start >= 0 && a.start <= anim.duration()))
    throw UsageError("--start " + Num(a.start) + " s is outside the animation's " +
                                Num(anim.duration()) + " s");
  const double frames_in_animation = std::floor((anim.duration() - a.start) * a.fps + 1e-9) + 1;
  if (!(frames_in_animation >= 1 && frames_in_animation <= 1e6))
    throw UsageError("--fps " + Num(a.fps) + " gives " + Num(frames_in_animation) +
                                " frames from --start; expected 1 to 1e6");
  const int available = static_cast<int>(frames_in_animation);
  const int count = a.count > 0 ? a.count : available;
  if (count > available)
    throw UsageError("--count " + Num(count) + ": only " + Num(available) +
                                " frames at " + Num(a.fps) + " fps from --start");
  // The folder's zeta.json says its frames are whole and this run's: it goes before the first
  // frame is written and comes back after the last, so a run killed or failing half way leaves
  // no zeta.json beside a mix of its frames and an earlier run's (a rerun with another seed left
  // frames of two designs under the new one's zeta.json).
  // Taken away again, while still empty, when the render fails before a frame (MadeFolders).
  const MadeFolders out_folders = MakeFoldersFor("--out", fs::path(a.out) / "zeta.json");

  render::RenderOptions ro;
  ro.threads = a.threads;
  render::Renderer renderer(zeta, ro);  // may still refuse ζ: the earlier run stays whole
  fs::remove(fs::path(a.out) / "zeta.json");
  // Frames of an earlier run beyond this one's (or in the other format) would read as its own; a
  // killed run's temporaries (frames, zeta.json) stayed for ever.
  const int stale = RemoveStaleFrames(a.out, [&](const std::string& name) {
    if (IsTemporaryOfStoppedProcess(name)) return true;
    for (const char* ext : {".jpg", ".png"}) {
      const auto n = FrameNumber(name, 3, ext);
      if (n && (*n >= count || a.format != std::string(ext + 1))) return true;
    }
    return false;
  });
  if (stale > 0) std::fprintf(stderr, "render: removed %d frames and temporaries left by an earlier run\n", stale);
  ProgressBar::Options bo;
  bo.label = "render";
  bo.unit = "frames";
  ProgressBar bar(bo);
  std::fprintf(stderr, "render: %s, %d frames at %.4g fps from %.3f s, %dx%d, %s %s\n", what.c_str(), count,
               a.fps, a.start, zeta.width, zeta.height, zeta.texture_kind.c_str(), zeta.texture_name.c_str());
  for (int k = 0; k < count; ++k) {
    const data::ClothFrame f = data::FrameAt(anim, a.start + k / a.fps);
    const cv::Mat image = [&] {
      try {
        return renderer.RenderFrame(f.V, f.F, f.UV);
      } catch (const std::invalid_argument& e) {  // the cloth's own values (not I/O)
        throw std::invalid_argument(what + ", frame at " + Num(a.start + k / a.fps) + " s: " + e.what());
      }
    }();
    char name[32];
    std::snprintf(name, sizeof(name), "%03d.%s", k, a.format.c_str());
    render::WriteFrameAtomic((fs::path(a.out) / name).string(), image, a.jpeg_quality);
    bar.Update(k + 1, count);
  }
  bar.Finish();
  sim::WriteFileAtomically((fs::path(a.out) / "zeta.json").string(), render::ToJson(zeta).dump(2) + "\n");
  std::printf("render: %d frames -> %s (%.1f ms/frame), zeta in %s/zeta.json\n", count, a.out.c_str(),
              1e3 * bar.Elapsed() / count, a.out.c_str());
  return 0;
}

const VerbRegistrar kRegistrar{"render", [](CLI::App& app) -> std::function<int()> {
  auto a = std::make_shared<RenderArgs>();
  auto* sub = app.add_subcommand("render",
                                 "render a cloth trajectory (.cwtraj) or OBJ frame sequence to frames (25 fps unless --fps)");
  sub->add_option("input", a->input, ".cwtraj file, or a folder with trajectory.cwtraj or NNNN_CC.obj frames")
      ->required();
  sub->add_option("--out", a->out, "output folder (000.jpg ..., zeta.json)")->required();
  auto* kind = sub->add_option("--kind", a->kind, "scene sampling when no --zeta: flag or cloth")
                   ->check(CLI::IsMember({"flag", "cloth"}))
                   ->capture_default_str();
  auto* seed = sub->add_option("--seed", a->seed, "seed of the render parameters zeta (not with --zeta)")
                   ->capture_default_str();
  auto* zeta = sub->add_option("--zeta", a->zeta, "zeta JSON file (or an example's label.json) instead of --seed");
  // A --zeta is rendered as given: a --seed or --kind beside it was accepted and ignored.
  zeta->excludes(seed);
  zeta->excludes(kind);
  // Both are about a given ζ: without --zeta they were accepted and ignored (a ζ drawn from --seed
  // takes the cloth's size and has a procedural backdrop, no photo).
  sub->add_flag("--keep-zeta", a->keep_zeta,
                "render --zeta as given even when its mesh_width/mesh_aspect_ratio are not the cloth's size "
                "(a label of a dataset made with another scene); refused otherwise")
      ->needs(zeta);
  sub->add_option("--backgrounds", a->backgrounds,
                  "folder of the background photo a --zeta names by file name (make-dataset --backgrounds)")
      ->needs(zeta);
  sub->add_option("--format", a->format, "jpg (or jpeg) or png")
      ->check(CLI::IsMember({"jpg", "jpeg", "png"}))
      ->capture_default_str();
  auto* quality =
      sub->add_option("--jpeg-quality", a->jpeg_quality, "JPEG quality")->check(CLI::Range(1, 100))->capture_default_str();
  sub->add_option("--start", a->start, "first frame's time in the animation [s]")->capture_default_str();
  sub->add_option("--count", a->count, "frames to render (0: to the end)")
      ->check(CLI::Range(0, 1000000))
      ->capture_default_str();
  sub->add_option("--fps", a->fps, "output frame rate [Hz]")->check(CLI::Range(1e-3, 1000.0))->capture_default_str();
  CLI::Option* frame_time = sub->add_option("--frame-time", a->frame_time, "time between OBJ frames [s] (0.001..10)")
                                ->check(CLI::Range(1e-3, 10.0))
                                ->capture_default_str();
  // Two digits, as simulate names them: -1 looked for 0000_-1.obj.
  CLI::Option* cloth = sub->add_option("--cloth", a->cloth, "which cloth (the CC of NNNN_CC.obj)")
                           ->check(CLI::Range(0, 99))
                           ->capture_default_str();
  sub->add_flag("--obj", a->obj, "read the folder's OBJ frames even if it has a trajectory");
  sub->add_option("--samples", a->samples, "anti-aliasing samples per pixel (0: zeta's; at most 1024)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  // Bounded: 99999999 threads threw bad_alloc after the old render's zeta.json was removed.
  sub->add_option("--threads", a->threads, "render threads (0: all cores; at most 1024)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  return [a, quality, frame_time, cloth] {
    a->frame_time_given = frame_time->count() > 0;
    a->cloth_given = cloth->count() > 0;
    // PNG is lossless: a quality beside it was accepted and ignored.
    if (a->format == "jpeg") a->format = "jpg";  // as make-dataset takes it
    if (quality->count() > 0 && a->format == "png")
      throw UsageError("--jpeg-quality is for JPEG frames; --format png is lossless");
    return Run(*a);
  };
}};

}  // namespace
}  // namespace clothwind::tools
