// clothwind make-session: a synthetic recorded field session as a rosbag, with the topics and
// messages the live camera_node and anemometer_node publish, so replay.launch treats it exactly as
// a real recording (header stamps = capture/arrival times; bag times = header stamps).
// --frames procedural (default, fast: an OpenCV-drawn flag) or rendered (the flag simulated in the
// session's wind and rendered by render/, with the anemometer's sentences from its sensor model
// sampling the same wind field: data/rendered_flag_generator.h).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <clothwind/RawSentence.h>

#include "common/atomic_file.h"
#include "data/rendered_flag_generator.h"
#include "output_paths.h"
#include "progress_bar.h"
#include "remove_on_interrupt.h"
#include "sensors/synthetic_session.h"
#include "verb_registry.h"
#include "usage_error.h"

namespace clothwind::tools {
namespace {

struct MakeSessionArgs {
  double minutes = 1.5;
  std::string out;
  uint64_t seed = 1;
  double fps = 30.0;
  int width = 320;
  int height = 240;
  double wind_mean = 4.0;
  double drop_probability = 0.0;
  double start_time = 1700000000.0;
  std::string compression = "lz4";
  std::string camera_frame = "camera_optical_frame";
  std::string anemometer_frame = "anemometer";
  std::string preview;
  std::string frames = "procedural";  // procedural | rendered
  data::RenderedSessionOptions rendered;
  int64_t zeta_seed = -1;  // -1: the session's seed
  bool overwrite = false;  // replace an existing --out
};

// A pinhole camera_info for the synthetic camera: ~60 degree horizontal field of view, no distortion.
sensor_msgs::CameraInfo MakeCameraInfo(int width, int height) {
  sensor_msgs::CameraInfo info;
  info.width = width;
  info.height = height;
  info.distortion_model = "plumb_bob";
  info.D = {0, 0, 0, 0, 0};
  const double f = 0.5 * width / std::tan(30.0 * M_PI / 180.0);
  const double cx = 0.5 * (width - 1), cy = 0.5 * (height - 1);
  info.K = {f, 0, cx, 0, f, cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {f, 0, cx, 0, 0, f, cy, 0, 0, 0, 1, 0};
  return info;
}

// Inputs: a; rendered_only: the options of --frames rendered that were given (their names).
int Run(const MakeSessionArgs& a, const std::vector<std::string>& rendered_only) {
  // Settings of the rendered flag do nothing to a procedural session: accepted and ignored, a
  // procedural bag came out of a command that asked for a rendered one's settings.
  if (a.frames != "rendered" && !rendered_only.empty())
    throw UsageError(rendered_only.front() + " is a setting of --frames rendered; this session's frames are " +
                                a.frames);
  // Bounded and long enough for a clip and a reading: infinity (cast to a frame count, undefined)
  // and a few milliseconds both wrote an empty bag and exited 0.
  if (!(a.minutes >= 0.05 && a.minutes <= 1440.0))
    throw UsageError("--minutes must be in 0.05..1440 (3 s to a day), got " + Num(a.minutes));
  if (!(std::isfinite(a.wind_mean) && a.wind_mean >= 0 && a.wind_mean <= 60))
    throw UsageError("--wind-mean must be in 0..60 m/s, got " + Num(a.wind_mean));
  // The session's own checks, named by option before the work (they said "synthetic session:
  // image must be ..." naming none, or came after a scene build).
  if (!(a.fps <= 1000.0)) throw UsageError("--fps must be at most 1000 Hz, got " + Num(a.fps));
  for (const auto& [option, value] : {std::pair<const char*, int>{"--width", a.width}, {"--height", a.height}})
    if (value < 16 || value > 16384)
      throw UsageError(std::string(option) + " must be in 16..16384 px, got " + Num(value));
  if (!(a.start_time >= 1.0 && a.start_time + a.minutes * 60.0 + 10.0 < 4294967295.0))
    throw UsageError("--start-time must be >= 1 s and leave the session within ROS time's 32-bit seconds, got " +
                                Num(a.start_time));
  if (!(a.drop_probability >= 0.0 && a.drop_probability < 1.0))
    throw UsageError("--drop-probability must be in [0, 1), got " + Num(a.drop_probability));
  // Every message carries its frame (REP 103): an empty one made a bag bag-check passed.
  if (a.camera_frame.empty()) throw UsageError("--camera-frame must not be empty");
  if (a.anemometer_frame.empty()) throw UsageError("--anemometer-frame must not be empty");
  if (!(std::isfinite(a.rendered.max_edge) && a.rendered.max_edge >= 0))
    throw UsageError("--max-edge must be a finite length >= 0 m (0: the scene's), got " +
                                Num(a.rendered.max_edge));
  // A bag file's name: "" and "dir/" generated the whole session and failed at the final rename
  // (the latter leaving dir/ made and empty).
  {
    const std::string name = std::filesystem::path(a.out).filename().string();
    if (name.empty() || name == "." || name == "..")
      throw UsageError("--out '" + a.out + "': expected a bag file name (e.g. session.bag)");
  }
  // The clip buffer's gap tolerance (0.1 s by default) makes every interval of a slower camera a
  // hole: such a session replays into no clip at all (exit 0, an empty report).
  if (!(a.fps >= 10.0))
    throw UsageError("--fps must be at least 10 Hz (a slower camera's every frame interval is a hole "
                                "to the clip buffer, and no clip forms), got " + Num(a.fps));
  if (a.zeta_seed < -1)
    throw UsageError("--zeta-seed must be >= 0 (or -1: the session's --seed), got " +
                                Num(a.zeta_seed));
  // --out checked before the long work: a folder failed only at the final rename (a rendered
  // session of hours lost), and an existing bag, perhaps a recorded field session, was replaced.
  RefuseFolderAsOutput("--out", a.out);
  {
    std::error_code ec;
    if (std::filesystem::exists(a.out, ec) && !a.overwrite)
      throw UsageError("--out " + a.out + " exists (a recorded session?); --overwrite replaces it");
  }
  // Checked before the long work, where a bad name used to be ignored after it (imwrite's result).
  std::string preview_extension;
  if (!a.preview.empty()) {
    preview_extension = std::filesystem::path(a.preview).extension().string();
    if (preview_extension.empty() || !cv::haveImageWriter(a.preview))
      throw UsageError("--preview " + a.preview +
                                  ": expected an image file name OpenCV can write (.png, .jpg, .ppm, ...)");
    // Its folder is made as --out's is, after the checks (it was refused where --out's was made).
    RefuseUnwritableFolder("--preview", a.preview);
    // The bag replaced the preview written beside it (exit 0, the image lost).
    if (SameFile(a.preview, a.out))
      throw UsageError("--preview " + a.preview + " is the bag --out names; give the image another name");
    // As the bag: an existing image (perhaps a recorded session's) was replaced without a word.
    RefuseExistingOutput("--preview", {a.preview}, a.overwrite);
  }
  sensors::SyntheticSessionOptions o;
  o.duration = a.minutes * 60.0;
  o.seed = a.seed;
  o.fps = a.fps;
  // The camera's jitter (2 ms at 30 fps) scaled to faster rates, which the default refused.
  if (a.fps > 0) o.frame_jitter = std::min(o.frame_jitter, 0.06 / a.fps);
  o.width = a.width;
  o.height = a.height;
  o.wind_base = a.wind_mean;
  o.drop_probability = a.drop_probability;
  o.start_time = a.start_time;
  std::shared_ptr<const data::RenderedFlagGenerator> rendered;
  if (a.frames == "rendered") {
    data::RenderedSessionOptions ro = a.rendered;
    ro.zeta_seed = a.zeta_seed >= 0 ? static_cast<uint64_t>(a.zeta_seed) : a.seed;
    rendered = std::make_shared<data::RenderedFlagGenerator>(o, ro);
  } else if (a.frames != "procedural") {
    throw UsageError("--frames: expected procedural or rendered, got '" + a.frames + "'");
  }
  const sensors::SyntheticSession session(o, rendered);
  // What was drawn must hold a clip (the clip buffer's 30 frames): a drop probability near 1 wrote
  // a bag without images, exit 0.
  if (session.frame_stamps().size() < 30)
    throw std::invalid_argument("the session holds " + Num(session.frame_stamps().size()) +
                                " frames after --drop-probability " + Num(a.drop_probability) +
                                ", fewer than one clip's 30");
  // And a stretch without holes as long as a clip (bag-check's rule, with the clip buffer's
  // defaults: gaps over 0.1 s break clips of 30 frames at 25 fps, 1.16 s): at 10 fps the frames'
  // jitter made half the intervals holes, and no clip formed.
  {
    const auto& t = session.frame_stamps();
    double longest = 0, run_start = t.front();
    for (size_t i = 1; i < t.size(); ++i) {
      if (t[i] - t[i - 1] > 0.1) run_start = t[i];
      longest = std::max(longest, t[i] - run_start);
    }
    if (longest < 1.16)
      throw UsageError("--fps " + Num(a.fps) + " with --drop-probability " +
                                  Num(a.drop_probability) + ": no stretch of frames without a gap over " +
                                  "0.1 s lasts a clip's 1.16 s (longest " + Num(longest) + " s)");
  }
  // Rendered sessions: the anemometer's sensor model samples the wind field the flag flew in.
  const std::vector<sensors::SyntheticReading> model_readings =
      rendered ? rendered->AnemometerReadings() : std::vector<sensors::SyntheticReading>{};
  // A bar for both kinds: a procedural hour is ~100 000 frames of drawing and compressing.
  ProgressBar::Options bo;
  bo.label = "make-session";
  bo.unit = "frames";
  auto bar = std::make_unique<ProgressBar>(bo);
  if (rendered) {
    std::fprintf(stderr, "make-session: rendering %zu frames of a simulated flag (%d vertices), %dx%d\n",
                 session.frame_stamps().size(), rendered->num_vertices(), a.width, a.height);
  }

  namespace fs = std::filesystem;
  const fs::path out(a.out);
  // Taken away again, while empty, when the session fails (MadeFolders).
  MadeFolders out_folders = MakeFoldersFor("--out", out);
  MadeFolders preview_folders = MakeFoldersFor("--preview", a.preview);
  // A run killed mid-write (Ctrl-C) leaves its temporary bag: clear those of dead processes.
  RemoveStaleTemporariesOf(a.out, [](const std::string& path) {
    std::fprintf(stderr, "make-session: removing %s, left by a run that stopped\n", path.c_str());
  });
  if (a.compression != "none" && a.compression != "lz4" && a.compression != "bz2")
    throw UsageError("--compression: expected none, lz4 or bz2, got '" + a.compression + "'");
  const std::string tmp = TemporaryNameFor(a.out);
  // Ctrl-C midway removes the temporary bag (it stayed until a later run into the same name).
  const RemoveOnInterrupt remove_on_interrupt(tmp);
  // Held by pointer: after a failed write (a full disk) the bag's close() throws again, and
  // rosbag::Bag's destructor calls close(), which then ended the program (std::terminate) and left
  // the temporary bag. On failure the object is abandoned instead (the verb is ending).
  auto bag_owner = std::make_unique<rosbag::Bag>();
  rosbag::Bag& bag = *bag_owner;
  bag.open(tmp, rosbag::bagmode::Write);
  if (a.compression == "lz4") bag.setCompression(rosbag::compression::LZ4);
  else if (a.compression == "bz2") bag.setCompression(rosbag::compression::BZ2);

  sensor_msgs::CameraInfo info = MakeCameraInfo(a.width, a.height);
  info.header.frame_id = a.camera_frame;
  const auto& stamps = session.frame_stamps();
  const auto& readings = rendered ? model_readings : session.readings();
  size_t fi = 0, ri = 0;
  double speed_sum = 0.0;
  std::vector<uchar> preview_bytes;  // the first frame, as --preview's format
  try {
    // Merge both streams in stamp order, as they were "recorded".
    while (fi < stamps.size() || ri < readings.size()) {
      const bool frame_next = ri >= readings.size() || (fi < stamps.size() && stamps[fi] <= readings[ri].stamp);
      if (frame_next) {
        const ros::Time t(stamps[fi]);
        const cv::Mat img = session.RenderFrame(fi);
        // Encoded now, written once the bag is in place: written here, a run stopped mid-bag left
        // the old bag beside the new run's preview.
        if (fi == 0 && !a.preview.empty() && !cv::imencode(preview_extension, img, preview_bytes))
          throw std::runtime_error("--preview " + a.preview + ": OpenCV could not encode the frame");
        sensor_msgs::Image msg;
        msg.header.seq = static_cast<uint32_t>(fi);
        msg.header.stamp = t;
        msg.header.frame_id = a.camera_frame;
        msg.height = img.rows;
        msg.width = img.cols;
        msg.encoding = "bgr8";
        msg.is_bigendian = 0;
        msg.step = img.cols * 3;
        msg.data.assign(img.data, img.data + img.total() * img.elemSize());
        bag.write("/camera/image_raw", t, msg);
        info.header.seq = msg.header.seq;
        info.header.stamp = t;
        bag.write("/camera/camera_info", t, info);
        ++fi;
        if (bar) bar->Update(static_cast<int64_t>(fi), static_cast<int64_t>(stamps.size()));
      } else {
        const auto& r = readings[ri];
        const ros::Time t(r.stamp);
        RawSentence msg;
        msg.header.seq = static_cast<uint32_t>(ri);
        msg.header.stamp = t;
        msg.header.frame_id = a.anemometer_frame;
        msg.data = r.sentence;
        msg.protocol = "nmea";
        bag.write("/anemometer/raw", t, msg);
        speed_sum += r.speed;
        ++ri;
      }
    }
    bag.close();
    // Durable before it takes its name (as WriteFileAtomically): after a power cut the name must
    // not point at an empty bag, which run-main would then reuse as the session.
    SyncFile(tmp);
    fs::rename(tmp, out);
    SyncDirectory(out.has_parent_path() ? out.parent_path().string() : ".");
    if (!a.preview.empty()) WriteFileAtomically(a.preview, preview_bytes.data(), preview_bytes.size());
    out_folders.Keep();
    preview_folders.Keep();
  } catch (const std::exception& e) {
    try {
      bag.close();
    } catch (...) {
    }
    (void)bag_owner.release();  // see above
    std::error_code ec;
    fs::remove(tmp, ec);
    // (A failure after the rename, syncing the folder, leaves the whole bag at its name.)
    throw std::runtime_error(a.out + ": " + e.what() +
                             (fs::exists(out, ec) ? "" : " (nothing written: the partial bag was removed)"));
  }
  if (bar) bar->Finish();
  std::printf("make-session: %s: %s frames, %.1f s, %zu frames %dx%d bgr8 at %.1f fps, %zu MWV sentences at 1 Hz "
              "(mean %.2f m/s), seed %llu, %.1f MB\n",
              a.out.c_str(), a.frames.c_str(), o.duration, stamps.size(), a.width, a.height, a.fps, readings.size(),
              readings.empty() ? NAN : speed_sum / readings.size(), static_cast<unsigned long long>(a.seed),
              fs::file_size(out) / 1e6);
  return 0;
}

const VerbRegistrar kRegistrar{"make-session", [](CLI::App& app) -> std::function<int()> {
  auto args = std::make_shared<MakeSessionArgs>();
  auto* sub = app.add_subcommand("make-session",
                                 "write a synthetic field session (camera + NMEA anemometer) as a rosbag");
  sub->add_option("--minutes", args->minutes, "session length [min] (0.05..1440)")->capture_default_str();
  sub->add_option("--out", args->out, "output bag (refused if it exists, unless --overwrite)")->required();
  sub->add_flag("--overwrite", args->overwrite, "replace an existing --out (and --preview)");
  sub->add_option("--seed", args->seed, "random seed (0..2^64-1)")->check(CLI::NonNegativeNumber)->capture_default_str();
  sub->add_option("--fps", args->fps, "camera rate [Hz] (above 10 to 1000: at 10, with the camera's jitter, no stretch lasts a clip)")->capture_default_str();
  sub->add_option("--width", args->width, "image width [px] (16..16384; rendered: 16..8192, width x height at most 2^24)")->capture_default_str();
  sub->add_option("--height", args->height, "image height [px] (16..16384; rendered: 16..8192)")->capture_default_str();
  sub->add_option("--wind-mean", args->wind_mean,
                  "long-term mean wind [m/s] (0..60; the wind is floored near calm, so below ~1 m/s the session's "
                  "mean comes out higher: 0 gives ~0.8)")
      ->capture_default_str();
  sub->add_option("--drop-probability", args->drop_probability, "chance a frame is lost, in [0, 1)")->capture_default_str();
  sub->add_option("--start-time", args->start_time, "stamp of the session start [s since epoch, >= 1; the session must end before 2^32 s]")
      ->capture_default_str();
  // Checked when parsed: a bad value used to leave the temporary bag behind.
  sub->add_option("--compression", args->compression, "none | lz4 | bz2")
      ->check(CLI::IsMember({"none", "lz4", "bz2"}))
      ->capture_default_str();
  sub->add_option("--camera-frame", args->camera_frame, "camera frame_id")->capture_default_str();
  sub->add_option("--anemometer-frame", args->anemometer_frame, "anemometer frame_id")->capture_default_str();
  sub->add_option("--preview", args->preview, "also write the first frame to this image file");
  sub->add_option("--frames", args->frames,
                  "procedural (fast drawing) or rendered (simulated flag + anemometer sensor model)")
      ->check(CLI::IsMember({"procedural", "rendered"}))->capture_default_str();
  const std::vector<CLI::Option*> rendered_only = {
      sub->add_option("--render-samples", args->rendered.samples, "rendered: anti-aliasing samples per pixel")
          ->capture_default_str(),
      sub->add_option("--max-edge", args->rendered.max_edge, "rendered: flag mesh resolution [m] (0: the scene's)")
          ->capture_default_str(),
      sub->add_option("--warmup", args->rendered.warmup, "rendered: flag simulated before the session starts [s]")
          ->capture_default_str(),
      sub->add_option("--zeta-seed", args->zeta_seed,
                      "rendered: seed of sun, sky, backdrop and flag design (default, or -1: --seed)"),
      sub->add_option("--camera-distance", args->rendered.camera_radius, "rendered: camera's horizontal distance from the flag's centre [m] (0.1..10000)")
          ->capture_default_str()};
  return [args, rendered_only] {
    std::vector<std::string> given;
    for (const CLI::Option* option : rendered_only)
      if (option->count() > 0) given.push_back(option->get_name());
    return Run(*args, given);
  };
}};

}  // namespace
}  // namespace clothwind::tools
