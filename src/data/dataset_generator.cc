#include "data/dataset_generator.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <algorithm>
#include <cctype>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "common/atomic_file.h"
#include "common/formatted.h"
#include "common/image_file.h"
#include "data/cloth_animation.h"
#include "data/contact_sheet.h"
#include "data/dataset_index.h"
#include "data/paths.h"
#include "render/camera.h"
#include "render/render_params.h"
#include "render/renderer.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"
#include "sim/simulate.h"
#include "sim/trajectory_io.h"

namespace clothwind::data {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

void Check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);  // (the verb's error line names make-dataset)
}

std::string TempPrefix(const std::string& name) { return "." + name + ".tmp-"; }

std::string TempDirName(const std::string& name) {
  static std::atomic<uint64_t> counter{0};
  return TempPrefix(name) + ProcessTag() + "-" + std::to_string(counter++);
}

// The simulation index of an example or temp folder name ("flag-000012-v1",
// ".flag-000012-v1.tmp-..."), or -1 when the name is not one of ours.
int64_t IndexOfName(const std::string& name, render::SceneKind kind) {
  const std::string prefix = render::SceneKindName(kind) + "-";
  size_t start = name[0] == '.' ? 1 : 0;
  if (name.compare(start, prefix.size(), prefix) != 0) return -1;
  start += prefix.size();
  size_t end = start;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end]))) ++end;
  if (end == start || end + 2 > name.size() || name.compare(end, 2, "-v") != 0) return -1;
  // More digits than an int64 holds is no name of ours (std::stoll threw a bare "stoll" at the
  // start of a run over a folder holding, say, ".flag-99999999999999999999-v0.tmp-x").
  if (end - start > 18) return -1;
  return std::stoll(name.substr(start, end - start));
}

// Everything loaded once and shared (read-only) by the workers.
struct Prepared {
  sim::SceneSetup setup;
  std::vector<Fabric> fabrics;  // ClothSim
  sim::Theta base_theta;
  SamplingRanges ranges;
  std::string scene_name;
  std::string scene_files;  // SceneFilesFingerprint: the contents the examples were simulated from
  std::string background_files;  // FilesFingerprint of the background photos ("" without photos)
  Eigen::Vector2d rest_size = Eigen::Vector2d::Zero();  // [m] the cloth's material-space extent
};

// FNV-1a (64 bit) of the bytes of every file a simulation reads: the scene, its cloths' meshes and
// materials, and ClothSim's fabrics, in that order, as "fnv1a64:<16 hex digits>". Why: the
// settings named the scene file only, so a scene or material edited between two runs (or two
// shards) mixed two physics in one dataset without a word. Any byte counts, comments included:
// resuming is refused rather than trusted.
// `what` names the kind of file in an error ("a file of the scene").
std::string FilesFingerprint(const std::vector<std::string>& files, const std::string& what) {
  uint64_t h = 14695981039346656037ull;
  auto add = [&](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read " + path + " (" + what + ")");
    char buffer[65536];
    while (in.read(buffer, sizeof(buffer)) || in.gcount() > 0) {
      for (std::streamsize k = 0; k < in.gcount(); ++k) {
        h ^= static_cast<unsigned char>(buffer[k]);
        h *= 1099511628211ull;
      }
    }
    h ^= 0xff;  // a file boundary, so moving bytes between files changes the value
    h *= 1099511628211ull;
  };
  for (const auto& f : files) add(f);
  char text[32];
  std::snprintf(text, sizeof(text), "fnv1a64:%016llx", static_cast<unsigned long long>(h));
  return text;
}

std::string SceneFilesFingerprint(const sim::Scene& scene, const std::vector<std::string>& extra_files) {
  std::vector<std::string> files = {scene.path};
  for (const auto& cloth : scene.cloths) {
    files.push_back(cloth.mesh);
    for (const auto& m : cloth.materials) files.push_back(m.data);
  }
  files.insert(files.end(), extra_files.begin(), extra_files.end());
  return FilesFingerprint(files, "a file of the scene");
}

std::vector<std::string> FabricNames(const std::vector<Fabric>& fabrics) {
  std::vector<std::string> names;
  for (const auto& f : fabrics) names.push_back(f.name);
  return names;
}

sim::MaterialMultipliers MultipliersOf(const sim::SceneMaterial& m) {
  sim::MaterialMultipliers mult;
  mult.density = m.density_mult;
  mult.stretching = m.stretching_mult;
  mult.bending = m.bending_mult;
  mult.thicken = m.thicken;
  mult.damping = m.damping;
  return mult;
}

Prepared Prepare(const DatasetOptions& o) {
  Prepared p;
  const std::string scene_path = o.scene.empty() ? DefaultScenePath(o.kind) : o.scene;
  // Warnings (a misspelt key, which the scene then runs without) go to stderr before a run of hours.
  const sim::Scene scene = sim::LoadScene(
      scene_path, [](const std::string& w) { std::fprintf(stderr, "make-dataset: warning: %s\n", w.c_str()); });
  if (scene.cloths.empty()) throw std::runtime_error(scene_path + ": field 'cloths' is empty");
  // One cloth is simulated, rendered and labelled: the others were dropped without a word.
  if (scene.cloths.size() > 1)
    throw std::runtime_error(scene_path + ": field 'cloths' holds " + std::to_string(scene.cloths.size()) +
                             " cloths; make-dataset makes examples of one (give a scene with one cloth)");
  if (std::abs(scene.frame_time * o.fps - 1.0) > 1e-9)
    throw std::runtime_error(scene_path + ": field 'frame_time' is " + std::to_string(scene.frame_time) +
                             " s, expected 1/fps = " + std::to_string(1.0 / o.fps) + " s");
  sim::BuildOptions build;
  build.max_edge = o.max_edge;
  p.setup = sim::BuildScene(scene, build);
  // Each clip is labelled with its steady wind speed: gusts (which only add wind) and turbulence
  // ran, moving the flag, while the label said the steady speed (4 m/s low at rate 0.5, 8 m/s).
  const sim::WindSpec& wind = p.setup.wind;
  if (wind.turbulence.intensity > 0 || (wind.gusts.rate > 0 && wind.gusts.amplitude > 0))
    throw std::runtime_error(scene_path + ": field 'wind' has " +
                             (wind.turbulence.intensity > 0 ? std::string("turbulence") : std::string("gusts")) +
                             "; make-dataset labels each clip with a steady wind speed, which they would not be "
                             "(give a scene with a steady wind)");
  const Eigen::MatrixXd& U = p.setup.cloths[0].mesh.U;
  if (U.rows() > 0 && U.cols() == 2) p.rest_size = (U.colwise().maxCoeff() - U.colwise().minCoeff()).transpose();
  p.base_theta = sim::SceneTheta(p.setup);
  p.scene_name = fs::path(scene_path).filename().string();
  p.ranges = o.ranges ? *o.ranges : DefaultRanges(o.kind);
  // Before any folder is made: a bad range fails the run here instead of failing every simulation
  // (the samplers check again, cheaply, for callers that use them directly).
  ValidateRanges(p.ranges);
  // Not for --add-tracks, which renders no clip.
  if (!o.add_tracks) {
    render::RenderParams framing = render::SampleRenderParams(o.kind, 0, {}, p.ranges.camera);
    if (p.rest_size.minCoeff() > 0) {
      framing.mesh_width = p.rest_size.x();
      framing.mesh_aspect_ratio = p.rest_size.x() / p.rest_size.y();
    }
    for (const std::string& w : CameraRangeWarnings(p.ranges.camera, p.rest_size.maxCoeff(),
                                                    render::MeshCentre(framing).z(), o.size))
      std::fprintf(stderr, "make-dataset: warning: %s\n", w.c_str());
  }
  if (o.kind == render::SceneKind::kCloth) {
    const std::string dir = o.materials_dir.empty() ? DefaultMaterialsDir() : o.materials_dir;
    p.fabrics = LoadFabrics(dir, scene_path, o.exclude_fabrics);
    // The paper's ClothSim draws from ArcSim's fabrics; this repository holds one (its folder is
    // the fallback without CLOTHWIND_SHARED_DIR), and a one-fabric ClothSim looked like any other.
    if (p.fabrics.size() < 2)
      std::fprintf(stderr,
                   "make-dataset: warning: ClothSim draws from %zu fabric%s in %s; ArcSim's fabrics (the paper's) "
                   "are in shared/arcsim/materials: set CLOTHWIND_SHARED_DIR or give --materials DIR\n",
                   p.fabrics.size(), p.fabrics.size() == 1 ? "" : "s", dir.c_str());
  }
  std::vector<std::string> fabric_files;
  for (const auto& f : p.fabrics) fabric_files.push_back(f.path);
  p.scene_files = SceneFilesFingerprint(scene, fabric_files);
  // The photos' bytes too: the settings name them by file name alone, so a resume (or a shard on
  // another machine) with other photos of the same names mixed two backdrops in one dataset.
  if (!o.background_images.empty()) p.background_files = FilesFingerprint(o.background_images, "a background photo");
  return p;
}

// The setup of one simulation: the shared one with this sample's fabric and wind direction.
sim::SceneSetup SetupFor(const Prepared& p, const SimulationSample& s, render::SceneKind kind) {
  sim::SceneSetup setup = p.setup;
  if (kind == render::SceneKind::kCloth) setup.cloths[0].material = p.fabrics[s.fabric_index].material;
  // ApplyTheta keeps the direction and sets the speed; a calm sample keeps +x.
  setup.wind.velocity = s.wind_velocity.norm() > 0 ? s.wind_velocity : Eigen::Vector3d::UnitX();
  return setup;
}

// An exclusive flock(2) on DIR/.index.lock while alive: the index is rebuilt from the folders
// present and written whole, and two shards (or --split runs) into one folder did that at once.
// One that listed the folder before the other's last rename and wrote after it left an index
// without that example. Under the lock, the last to write listed the folder after every rename
// that finished before it. (Linux's NFS client maps flock to the server's POSIX locks.) Every
// writer of index.json and contact_sheet.png holds it while its temporary exists, so under it a
// temporary of theirs belongs to a run that stopped.
// The lock guards; it is not needed to go on: opened read-only (another user's lock file, 0644,
// opens so), and where it cannot be had (an NFS mount without lockd: ENOLCK) the run says so and
// goes on unlocked rather than lose hours of simulations at their end.
class IndexLock {
 public:
  explicit IndexLock(const std::string& dir) {
    const std::string path = (fs::path(dir) / ".index.lock").string();
    fd_ = ::open(path.c_str(), O_RDONLY | O_CREAT | O_CLOEXEC, 0666);
    if (fd_ < 0) {
      std::fprintf(stderr, "make-dataset: cannot open %s (%s): the index is rebuilt unlocked\n", path.c_str(),
                   std::strerror(errno));
      return;
    }
    int error = ::flock(fd_, LOCK_EX | LOCK_NB) == 0 ? 0 : errno;
    if (error == 0) return;
    if (error == EWOULDBLOCK) {
      std::fprintf(stderr, "make-dataset: waiting for another run's index rebuild (%s)\n", path.c_str());
      do {
        error = ::flock(fd_, LOCK_EX) == 0 ? 0 : errno;
      } while (error == EINTR);
      if (error == 0) return;
    }
    std::fprintf(stderr, "make-dataset: cannot lock %s (%s): the index is rebuilt unlocked\n", path.c_str(),
                 std::strerror(error));
    ::close(fd_);
    fd_ = -1;
  }
  ~IndexLock() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the lock
  }
  IndexLock(const IndexLock&) = delete;
  IndexLock& operator=(const IndexLock&) = delete;

 private:
  int fd_ = -1;
};

// Removes the index's and contact sheet's temporaries in `dir` left by runs that stopped while
// writing them (each killed run left one more). Called under IndexLock, which their writers hold:
// a live run's on another machine (another boot, so "stopped" by its tag alone) is never there.
void RemoveIndexTemporariesOfStoppedRuns(const std::string& dir) {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    size_t at = 0;
    if (IsTemporaryOfStoppedProcess(name, &at) &&
        (name.substr(0, at) == "index.json" || name.substr(0, at) == "contact_sheet.png")) {
      std::error_code ec;
      fs::remove(e.path(), ec);
    }
  }
}

// Simulation i's sample, as this run draws it.
SimulationSample SampleOf(const DatasetOptions& o, const Prepared& p, int64_t i) {
  return o.kind == render::SceneKind::kFlag ? SampleFlagSimulation(p.base_theta, o.seed, i, p.ranges)
                                            : SampleClothSimulation(p.fabrics, o.seed, i, p.ranges);
}

// View v's rendering parameters of sample s, as this run renders them.
render::RenderParams ViewOf(const DatasetOptions& o, const Prepared& p, const SimulationSample& s, int v) {
  render::RenderParams zeta = SampleView(o.kind, s.seed, v, o.views, o.background_images, p.ranges.camera);
  // ζ's pole, rod and camera aim assume the scene's usual cloth (3 x 2 m flag, 1 x 1 m cloth): a
  // --scene of another size flew beside its pole, framed wrongly, without a word. Its rest size
  // is taken instead when more than 5 % off (the usual meshes keep ζ, and their frames, as they
  // were), as `clothwind render --seed` does.
  if (p.rest_size.minCoeff() > 0 && !render::MeshSizeMismatch(zeta, p.rest_size).empty())
    render::SetMeshSize(p.rest_size, &zeta);
  if (o.samples > 0) zeta.samples = o.samples;
  zeta.width = zeta.height = o.size;
  zeta.fps = o.fps;
  return zeta;
}

// Frame k's file name in an example folder: "%03d.<ext>", the labels' frame_pattern.
std::string ExampleFrameFile(size_t k, const std::string& ext) {
  char file[32];
  std::snprintf(file, sizeof(file), "%03zu.", k);
  return file + ext;
}


// Whether two label values agree: numbers within a relative 1e-9 (a label's doubles come back
// from their JSON text), objects and arrays element by element, the rest exactly.
bool JsonNear(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.is_number() && b.is_number()) {
    const double x = a.get<double>(), y = b.get<double>();
    return std::abs(x - y) <= 1e-9 * std::max(1.0, std::abs(y));
  }
  if (a.is_object() && b.is_object()) {
    if (a.size() != b.size()) return false;
    for (auto it = a.begin(); it != a.end(); ++it)
      if (!b.contains(it.key()) || !JsonNear(it.value(), b[it.key()])) return false;
    return true;
  }
  if (a.is_array() && b.is_array()) {
    if (a.size() != b.size()) return false;
    for (size_t k = 0; k < a.size(); ++k)
      if (!JsonNear(a[k], b[k])) return false;
    return true;
  }
  return a == b;
}

// Reads a tracks.json's top level up to its "world" key: the "grid" before it (the writer's keys
// come sorted) and whether "world" is there, without parsing the arrays after it (95 % of the
// file: a --reindex of flagsim-e5's 19,208 examples parsed 1.8 GB for two keys, 40 s).
class TracksHeadSax : public nlohmann::json_sax<nlohmann::json> {
 public:
  std::vector<int64_t> grid;
  bool grid_seen = false, grid_bad = false, world = false;

  bool null() override { return Value(); }
  bool boolean(bool) override { return Value(); }
  bool number_integer(number_integer_t v) override {
    if (in_grid_ && depth_ == 2) grid.push_back(v);
    return true;
  }
  bool number_unsigned(number_unsigned_t v) override {
    if (in_grid_ && depth_ == 2) grid.push_back(static_cast<int64_t>(v));
    return true;
  }
  bool number_float(number_float_t, const string_t&) override { return Value(); }
  bool string(string_t&) override { return Value(); }
  bool binary(binary_t&) override { return Value(); }
  bool start_object(std::size_t) override { return Open(false); }
  bool end_object() override { return Close(); }
  bool start_array(std::size_t) override { return Open(true); }
  bool end_array() override { return Close(); }
  bool key(string_t& k) override {
    if (depth_ != 1) return true;
    if (k == "world") {
      world = true;
      return false;  // stop: what follows is not needed
    }
    key_ = k;
    return true;
  }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }

 private:
  bool Value() {
    if (in_grid_) grid_bad = true;
    return true;
  }
  bool Open(bool array) {
    ++depth_;
    if (depth_ == 2 && key_ == "grid") {
      grid_seen = true;
      in_grid_ = array;
      grid_bad = !array;
    } else if (in_grid_) {
      grid_bad = true;
    }
    return true;
  }
  bool Close() {
    if (depth_ == 2) in_grid_ = false;
    --depth_;
    return true;
  }
  int depth_ = 0;
  bool in_grid_ = false;
  std::string key_;
};

// Whether an example's tracks.json holds the points' positions ("world"; data/clip_tracks.h).
// Files written before them, and unreadable ones, do not: --add-tracks makes them again.
// And whether they are of `grid`: --add-tracks with another grid made a dataset of two grids.
// The top level is read up to "world" (TracksHeadSax) and the file's last byte must close it: a
// copy cut short is not whole. A file of another key order is parsed whole.
bool TracksHaveWorld(const fs::path& file, const TrackGrid& grid) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;
  // The last byte that is not white space closes the top-level object (no other object is in it).
  in.seekg(0, std::ios::end);
  for (std::streamoff back = 1; back <= in.tellg(); ++back) {
    in.seekg(-back, std::ios::end);
    const int c = in.get();
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    if (c != '}') return false;
    break;
  }
  in.clear();
  in.seekg(0);
  TracksHeadSax head;
  nlohmann::json::sax_parse(in, &head);
  if (head.world && head.grid_seen)
    return !head.grid_bad && head.grid == std::vector<int64_t>{grid.cols, grid.rows};
  in.clear();
  in.seekg(0);
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("world") && j.value("grid", nlohmann::json()) == nlohmann::json({grid.cols, grid.rows});
}

void CheckFinite(const sim::Trajectory& t) {
  for (int f = 0; f < t.num_frames(); ++f) {
    if (!t.frames[f].allFinite() || t.frames[f].cwiseAbs().maxCoeff() > 1e3)
      throw std::runtime_error("simulation diverged at frame " + std::to_string(f));
  }
}

// Writes one example: frames and label.json into a temporary folder, renamed into place.
void WriteExample(const std::string& out, const std::string& name, const std::vector<cv::Mat>& images,
                  const nlohmann::json& label, const nlohmann::json& tracks, const DatasetOptions& o) {
  const fs::path tmp = fs::path(out) / TempDirName(name);
  fs::create_directory(tmp);
  try {
    std::vector<int> params;
    if (o.frame_ext == "jpg") params = {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality};
    cv::Mat grey;
    std::vector<uchar> encoded;
    for (size_t k = 0; k < images.size(); ++k) {
      const std::string file = ExampleFrameFile(k, o.frame_ext);
      // PGM holds one channel: the grey the SDN reads (cv::imread's IMREAD_GRAYSCALE weights).
      if (o.frame_ext == "pgm") cv::cvtColor(images[k], grey, cv::COLOR_BGR2GRAY);
      if (!cv::imencode("." + o.frame_ext, o.frame_ext == "pgm" ? grey : images[k], encoded, params))
        throw std::runtime_error("cannot encode " + (tmp / file).string());
      // fsync'ed, as label.json is: a power cut must not leave an example whose label says it is
      // complete (what a resumed run checks) beside empty frames.
      WriteFileDurably((tmp / file).string(), encoded.data(), encoded.size());
    }
    if (!tracks.is_null()) sim::WriteFileAtomically((tmp / "tracks.json").string(), tracks.dump() + "\n");
    sim::WriteFileAtomically((tmp / "label.json").string(), label.dump(2) + "\n");
    // A folder of this name without label.json (written last) or without one of its frames is
    // an unfinished copy, e.g. an interrupted cp or rsync of a dataset: the rename failed on it
    // ("Directory not empty") at every resume. It is incomplete by this writer's own rule, so it
    // is replaced.
    const fs::path target = fs::path(out) / name;
    if (fs::exists(target)) {
      const bool labelled = fs::exists(target / "label.json");
      if (labelled && FramesPresent(target, static_cast<int>(images.size()), FramePattern(o.frame_ext)))
        throw std::runtime_error(target.string() + " is already complete: not replaced");
      std::fprintf(stderr, "make-dataset: %s has %s (unfinished): made again\n", target.c_str(),
                   labelled ? "frames missing" : "no label.json");
      fs::remove_all(target);
    }
    fs::rename(tmp, target);
    SyncDirectory(out);
  } catch (...) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw;
  }
}

// --add-tracks: throws unless `rendered` (the example's last frame rendered again from its replayed
// simulation) matches the stored one within kMaxReplayGreyDifference.
void CheckReplay(const fs::path& example, int last_frame, const std::string& ext, const cv::Mat& rendered) {
  const fs::path path = example / ExampleFrameFile(last_frame, ext);
  std::string why;
  const cv::Mat stored = common::ReadImageFile(path, cv::IMREAD_GRAYSCALE, &why);
  if (stored.empty()) throw std::runtime_error("cannot read " + path.string() + " (" + why + ")");
  cv::Mat grey;
  cv::cvtColor(rendered, grey, cv::COLOR_BGR2GRAY);
  if (stored.size() != grey.size())
    throw std::runtime_error(path.string() + " is " + std::to_string(stored.cols) + "x" +
                             std::to_string(stored.rows) + " px, the dataset's settings render " +
                             std::to_string(grey.cols) + "x" + std::to_string(grey.rows));
  cv::Mat diff;
  cv::absdiff(stored, grey, diff);
  const double mean = cv::mean(diff)[0];
  if (mean > kMaxReplayGreyDifference)
    throw std::runtime_error(path.string() + " differs from the replayed simulation's frame by " +
                             std::to_string(mean) + " grey levels on average (at most " +
                             std::to_string(kMaxReplayGreyDifference) +
                             " expected): the example was made by another simulator or renderer, so no "
                             "tracks are added to it");
}

// The dataset's settings record the cameras only where they differ from Table 2's, so the
// datasets made before cameras were an option keep their settings and resume as they were.
nlohmann::json RangesJson(const SamplingRanges& r, render::SceneKind kind) {
  nlohmann::json j{{"wind_min", r.wind_min},
                   {"wind_max", r.wind_max},
                   {"area_weight_factor", r.area_weight_factor},
                   {"bending_factor", r.bending_factor},
                   {"bending_jitter", r.bending_jitter},
                   {"cloth_area_weight_min", r.cloth_area_weight_min},
                   {"cloth_area_weight_max", r.cloth_area_weight_max}};
  if (r.camera != render::TableTwoCameraRanges(kind))
    j["camera"] = {{"height", {r.camera.height_min, r.camera.height_max}},
                   {"radius", {r.camera.radius_min, r.camera.radius_max}},
                   {"angle_max_deg", r.camera.angle_max_deg}};
  return j;
}

nlohmann::json IndexHeader(const DatasetOptions& o, const nlohmann::json& settings) {
  return {{"format", "clothwind-dataset"},
          {"version", kFormatVersion},
          {"kind", render::SceneKindName(o.kind)},
          {"generator", {{"name", kGeneratorName}, {"version", kGeneratorVersion}}},
          {"dataset", settings},
          {"count", o.count},
          {"clips", nlohmann::json::array()}};
}

// Throws when DIR already holds a dataset whose settings differ from this run's, either way: a
// setting of the folder's that this run lacks counts too (a dataset made with --tracks resumed
// without them made examples without tracks.json and dropped "tracks" from the header).
// `ignored`: a key compared on neither side (--add-tracks gives examples theirs).
// Settings recorded since a later version ("scene_files"): a folder whose header lacks them was
// made before and is taken as it is (the final index records them).
// --add-tracks (`ignored` "tracks") still refuses another grid than the header's.
void CheckCompatible(const std::string& dir, const nlohmann::json& settings, const std::string& ignored = "") {
  const nlohmann::json existing = ReadIndex(dir);
  if (existing.is_null() || !existing.contains("dataset")) return;
  const nlohmann::json& old = existing["dataset"];
  if (ignored == "tracks" && old.contains("tracks") && settings.contains("tracks") && old["tracks"] != settings["tracks"])
    throw std::runtime_error((fs::path(dir) / "index.json").string() + ": field 'dataset.tracks' is " +
                             old["tracks"].dump() + " but this run adds " + settings["tracks"].dump() +
                             " (a dataset holds one grid: --add-tracks with the header's, or another --out)");
  for (auto it = old.begin(); it != old.end(); ++it) {
    if (it.key() == ignored || settings.contains(it.key())) continue;
    const bool grid = it.key() == "tracks" && it.value().is_array() && it.value().size() == 2;
    throw std::runtime_error((fs::path(dir) / "index.json").string() + ": field 'dataset." + it.key() + "' is " +
                             it.value().dump() + " but this run has none (" +
                             (grid ? "resume with --tracks " + it.value()[0].dump() + "x" + it.value()[1].dump()
                                   : std::string("resume with the same settings, or use another --out")) +
                             ")");
  }
  for (auto it = settings.begin(); it != settings.end(); ++it) {
    if (it.key() == ignored || ((it.key() == "scene_files" || it.key() == "background_files") && !old.contains(it.key())))
      continue;
    if (!old.contains(it.key()) || old[it.key()] != it.value())
      throw std::runtime_error((fs::path(dir) / "index.json").string() + ": field 'dataset." + it.key() +
                               "' is " + (old.contains(it.key()) ? old[it.key()].dump() : "missing") +
                               " but this run asks for " + it.value().dump() +
                               (it.key() == "tracks" && !old.contains("tracks")
                                    ? " (the examples there were made without tracks: give them theirs with "
                                      "--add-tracks, then resume with --tracks)"
                                    : it.key() == "scene_files"
                                          ? " (the scene, a mesh or a material file changed since the dataset was "
                                            "made: restore them, or use another --out)"
                                    : it.key() == "background_files"
                                          ? " (the background photos differ from those the dataset was made with: "
                                            "one added, removed, renamed or changed; give those, or use another "
                                            "--out)"
                                          : it.key() == "generator_version"
                                                ? " (an older make-dataset made those frames, and this one "
                                                  "renders them differently: make the dataset again in another "
                                                  "--out; docs/datasets.md, generator_version)"
                                                : " (resume with the same settings, or use another --out)"));
  }
}

// Throws unless DIR's index (`existing`, not null) is a make-dataset dataset of this run's kind
// whose count is at most this run's. A recorded session's or a toy dataset's index was rewritten
// as FlagSim's (their own fields dropped); a smaller --count left the header's count below the
// simulations the index lists.
void CheckIndexIsThisKind(const std::string& dir, const nlohmann::json& existing, const DatasetOptions& o) {
  const std::string file = (fs::path(dir) / "index.json").string();
  const std::string kind = render::SceneKindName(o.kind);
  if (!existing.is_object() || !existing.contains("dataset"))
    throw std::runtime_error(file + ": no field 'dataset': not a dataset make-dataset made (recordings and toy "
                             "datasets keep their own index); use another --out");
  if (existing.value("kind", nlohmann::json()) != kind)
    throw std::runtime_error(file + ": field 'kind' is " + existing.value("kind", nlohmann::json()).dump() +
                             ", this run makes \"" + kind + "\" (use another --out)");
  const nlohmann::json count = existing.value("count", nlohmann::json());
  if (count.is_number_integer() && count.get<int64_t>() > o.count)
    throw std::runtime_error(file + ": field 'count' is " + count.dump() + " but this run asks for " +
                             std::to_string(o.count) + " (resume with --count " + count.dump() +
                             " or more: a smaller count would leave the header below the simulations listed)");
}

// Throws unless the example folder of simulation i, view v has a label.json that says it was
// made as this run would make it: FlagSim or ClothSim, global and simulation seed, frames, size,
// format, rate, warm-up, scene and mesh; the views, the split, the fabric, θ and ζ drawn for it;
// the generator's version (not for --add-tracks, which keeps the frames that are there); and a
// tracks.json when this run makes tracks. Why: without an index (the e5 recipe copies another
// dataset's examples and drops its index) nothing else compared them, and examples of other
// settings were counted complete: another binary's frames, --views 2 over a copy of one view,
// --wind-max 5 over 0-10 m/s, --tracks over examples made without (whose header then claimed
// tracks), or other --val/--test fractions (one simulation in two splits).
void CheckExampleLabel(const std::string& dir, int64_t i, int v, const DatasetOptions& o, const Prepared& p) {
  const std::string name = ExampleName(o.kind, i, v);
  const SimulationSample s = SampleOf(o, p, i);
  const uint64_t simulation_seed = s.seed;
  const fs::path file = fs::path(dir) / name / "label.json";
  std::ifstream in(file);
  const nlohmann::json label = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!label.is_object()) throw std::runtime_error(file.string() + ": not a JSON object (remove the folder to make it again)");
  const nlohmann::json sim = label.value("simulation_settings", nlohmann::json::object());
  const double frame_time = 1.0 / o.fps;
  const std::vector<std::pair<std::string, std::pair<nlohmann::json, nlohmann::json>>> fields = {
      {"dataset", {label.value("dataset", nlohmann::json()), render::SceneKindName(o.kind)}},
      {"dataset_seed", {label.value("dataset_seed", nlohmann::json()), o.seed}},
      {"seed", {label.value("seed", nlohmann::json()), simulation_seed}},
      {"num_frames", {label.value("num_frames", nlohmann::json()), o.frames}},
      {"width", {label.value("width", nlohmann::json()), o.size}},
      {"height", {label.value("height", nlohmann::json()), o.size}},
      {"frame_pattern", {label.value("frame_pattern", nlohmann::json()), FramePattern(o.frame_ext)}},
      {"simulation_settings.scene", {sim.value("scene", nlohmann::json()), p.scene_name}},
      {"simulation_settings.vertices", {sim.value("vertices", nlohmann::json()), p.setup.cloths[0].mesh.V.rows()}},
      {"views", {label.value("views", nlohmann::json()), o.views}},
      {"split", {label.value("split", nlohmann::json()), SplitOf(simulation_seed, o.val_fraction, o.test_fraction)}},
      {"fabric", {label.value("fabric", nlohmann::json()), s.fabric}},
      {"generator.version",
       {o.add_tracks || !label.contains("generator") || !label["generator"].is_object()
            ? nlohmann::json()
            : label["generator"].value("version", nlohmann::json()),
        kGeneratorVersion}},
  };
  for (const auto& [field, values] : fields) {
    // A field the label lacks (a label of an older generator) is not compared.
    if (!values.first.is_null() && values.first != values.second)
      throw std::runtime_error(file.string() + ": field '" + field + "' is " + values.first.dump() + ", this run makes " +
                               values.second.dump() + " (the example was made with other settings: resume with "
                               "theirs, or use another --out)");
  }
  // θ and ζ as drawn for this simulation and view (the ranges, cameras and backgrounds), compared
  // by value: a label holds them as JSON text.
  nlohmann::json theta = nlohmann::json::array();
  for (int k = 0; k < sim::kNumParameters; ++k) theta.push_back(s.theta[k]);
  const std::vector<std::pair<std::string, nlohmann::json>> drawn = {
      {"theta", theta}, {"zeta", ZetaLabelJson(ViewOf(o, p, s, v))}};
  for (const auto& [field, expected] : drawn) {
    if (label.contains(field) && !JsonNear(label[field], expected))
      throw std::runtime_error(file.string() + ": field '" + field + "' is " + label[field].dump() +
                               ", this run draws " + expected.dump() +
                               " (the example was made with other ranges, cameras or backgrounds: resume with "
                               "theirs, or use another --out)");
  }
  // Asked of a finished example only: one whose frames a copy has not brought yet is made again.
  if (o.tracks && !o.add_tracks && FramesPresent(fs::path(dir) / name, o.frames, FramePattern(o.frame_ext)) &&
      !fs::exists(fs::path(dir) / name / "tracks.json"))
    throw std::runtime_error((fs::path(dir) / name).string() +
                             " has no tracks.json, and this run makes tracks (give the examples theirs with "
                             "--add-tracks, then resume with --tracks)");
  if (label.contains("frame_rate") && !JsonNear(label["frame_rate"], o.fps))
    throw std::runtime_error(file.string() + ": field 'frame_rate' is " + label.value("frame_rate", nlohmann::json()).dump() +
                             ", this run makes " + std::to_string(o.fps) + " Hz (resume with its settings, or use another --out)");
  const double warmup = std::lround(o.warmup / frame_time) * frame_time;
  if (sim.contains("warmup") && !JsonNear(sim["warmup"], warmup))
    throw std::runtime_error(file.string() + ": field 'simulation_settings.warmup' is " +
                             sim.value("warmup", nlohmann::json()).dump() + ", this run makes " + std::to_string(warmup) +
                             " s (resume with its settings, or use another --out)");
}

// The first five names, comma-separated, and ", ..." when there are more.
std::string FirstNames(const std::vector<std::string>& names) {
  std::string listed;
  for (size_t k = 0; k < names.size() && k < 5; ++k) listed += (k ? ", " : "") + names[k];
  return names.size() > 5 ? listed + ", ..." : listed;
}

// Says which examples the index left out for frames missing (BuildIndex), so that a merge whose
// copy has not finished, or a deleted frame, is seen rather than silently smaller.
void SayIncomplete(const char* who, const std::vector<std::string>& incomplete) {
  if (incomplete.empty()) return;
  std::fprintf(stderr, "%s: %zu example%s left out of the index, %s frames not all there: %s (a run of %s "
               "shard makes %s again)\n",
               who, incomplete.size(), incomplete.size() == 1 ? "" : "s", incomplete.size() == 1 ? "its" : "their",
               FirstNames(incomplete).c_str(), incomplete.size() == 1 ? "its" : "their",
               incomplete.size() == 1 ? "it" : "them");
}

}  // namespace

void ValidateDatasetOptions(const DatasetOptions& o) {
  // At most a million: an example's name holds six digits of its simulation (flag-000123-v0), and
  // e5 holds 6,000. 1e11 hung without a word, building its to-do list (~800 GB).
  Check(o.count >= 0 && o.count <= kMaxSimulations,
        "--count must be in 0.." + std::to_string(kMaxSimulations) + ", got " + std::to_string(o.count));
  Check(o.views >= 1 && o.views <= 64, "--views must be in 1..64");
  Check(!o.out.empty(), "--out is required");
  Check(o.shards >= 1 && o.shard >= 0 && o.shard < o.shards, "--shard i/N needs 0 <= i < N");
  // TBB runs at most the cores' threads: --jobs 100000 ran on 2 and reported "on 100000 jobs".
  Check(o.jobs >= 0 && o.jobs <= kMaxJobs,
        "--jobs must be in 0.." + std::to_string(kMaxJobs) + " (0: all cores), got " + std::to_string(o.jobs));
  // Finite as well: infinity passed ">= 0", ran as a warm-up of 0 (lround(inf)) and went into the
  // header as null, which every later run was then refused against.
  Check(std::isfinite(o.warmup) && o.warmup >= 0 && o.warmup <= 3600, "--warmup must be in 0..3600 s");
  // At most what a label may hold (dataset_index.cc): more ran for hours and then every example
  // was refused when the index was built.
  Check(o.frames >= 1 && o.frames <= 100000, "--frames must be in 1..100000 (a label's bound)");
  Check(std::isfinite(o.fps) && o.fps > 0 && o.fps <= 1000, "--fps must be in (0, 1000] Hz");
  // The first kept frame is a whole frame: a warm-up between two was rounded without a word, and
  // the header recorded the value asked for while the labels recorded the rounded one.
  Check(std::abs(o.warmup * o.fps - std::round(o.warmup * o.fps)) < 1e-6,
        "--warmup must be a whole number of frames (a multiple of 1/fps = " + FormattedNumber(1.0 / o.fps) +
            " s), got " + FormattedNumber(o.warmup) + " s");
  Check(o.samples >= 0 && o.samples <= 1024, "--samples must be in 0..1024 (0: zeta's default)");
  Check(o.size >= 16 && o.size <= 4096, "--size must be in 16..4096 px");
  // Each job renders an example's frames in memory (RenderAnimation, 3 bytes a pixel) before
  // writing them: refused past 16 GiB an example, which no machine here holds once per job.
  Check(static_cast<double>(o.frames) * o.size * o.size * 3 <= 16.0 * (1ull << 30),
        "--frames x --size^2 x 3 bytes (one example's frames, held in memory while it is written) must be at "
        "most 16 GiB, got " + FormattedNumber(static_cast<double>(o.frames) * o.size * o.size * 3 / (1ull << 30)) +
            " GiB");
  Check(o.frame_ext == "jpg" || o.frame_ext == "png" || o.frame_ext == "pgm",
        "frame format must be jpg, png or pgm");
  Check(o.jpeg_quality >= 1 && o.jpeg_quality <= 100, "--jpeg-quality must be in 1..100");
  Check(std::isfinite(o.max_edge) && o.max_edge >= 0, "--max-edge must be a finite length >= 0 m");
  Check(!o.add_tracks || o.tracks, "--add-tracks needs the grid of the tracks (--tracks COLSxROWS)");
  Check(o.split.empty() || o.split == "train" || o.split == "val" || o.split == "test",
        "--split must be train, val or test");
  // Checked before the index's header records them: a run refused for them later would leave a
  // folder whose header every corrected run is refused against.
  Check(o.val_fraction >= 0 && o.test_fraction >= 0 && o.val_fraction + o.test_fraction <= 1,  // NaN fails too
        "--val and --test must be fractions >= 0 that add up to at most 1 (got " + FormattedNumber(o.val_fraction) +
            " and " + FormattedNumber(o.test_fraction) + ")");
}


std::vector<Fabric> LoadFabrics(const std::string& folder, const std::string& scene_path,
                                const std::vector<std::string>& exclude) {
  if (!fs::is_directory(folder))
    throw std::runtime_error("materials folder " + folder + (fs::exists(folder) ? " is a file, expected a folder of ArcSim material files" : " not found"));
  const sim::Scene scene = sim::LoadScene(scene_path, [](const std::string&) {});
  const sim::MaterialMultipliers mult =
      scene.cloths.at(0).materials.empty() ? sim::MaterialMultipliers{} : MultipliersOf(scene.cloths[0].materials[0]);
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder)) {
    if (e.path().extension() != ".json") continue;
    const std::string stem = e.path().stem().string();
    if (std::find(exclude.begin(), exclude.end(), stem) != exclude.end()) continue;
    files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) throw std::runtime_error("materials folder " + folder + ": no *.json material");
  std::vector<Fabric> fabrics;
  for (const auto& f : files)
    fabrics.push_back({f.stem().string(), f.string(), sim::LoadArcSimMaterial(f.string(), mult)});
  return fabrics;
}

nlohmann::json DatasetSettingsJson(const DatasetOptions& o, const std::vector<std::string>& fabric_names,
                                   const std::string& scene_files, const std::string& background_files) {
  const std::string scene_path = o.scene.empty() ? DefaultScenePath(o.kind) : o.scene;
  nlohmann::json backgrounds = nlohmann::json::array();
  for (const auto& b : o.background_images) backgrounds.push_back(fs::path(b).filename().string());
  nlohmann::json settings = {{"kind", render::SceneKindName(o.kind)},
          {"seed", o.seed},
          {"views", o.views},
          {"frames", o.frames},
          {"fps", o.fps},
          {"warmup", o.warmup},
          {"max_edge", o.max_edge},
          {"size", o.size},
          {"samples", o.samples},
          {"frame_format", o.frame_ext},
          {"jpeg_quality", o.jpeg_quality},
          {"val_fraction", o.val_fraction},
          {"test_fraction", o.test_fraction},
          {"ranges", RangesJson(o.ranges ? *o.ranges : DefaultRanges(o.kind), o.kind)},
          {"scene", fs::path(scene_path).filename().string()},
          {"fabrics", fabric_names},
          {"background_images", backgrounds},
          {"generator_version", kGeneratorVersion}};
  if (o.tracks) settings["tracks"] = {o.tracks->cols, o.tracks->rows};
  if (!scene_files.empty()) settings["scene_files"] = scene_files;
  if (!background_files.empty()) settings["background_files"] = background_files;
  // ClothSim's wind has one direction since 2026-12-06; a folder made with directions over the
  // circle lacks this and is refused on resume rather than mixed.
  if (o.kind == render::SceneKind::kCloth) settings["wind_direction_deg"] = kClothWindAzimuth * 180 / M_PI;
  return settings;
}

int64_t ReindexDataset(const std::string& dir, bool contact_sheet, const std::function<void(int, int)>& progress) {
  nlohmann::json index = ReadIndex(dir);
  if (index.is_null()) throw std::runtime_error(dir + "/index.json not found: not a dataset folder");
  // Compared as JSON: value("kind", "") threw a bare type error on a kind of another type.
  const nlohmann::json kind = index.is_object() && index.contains("kind") ? index["kind"] : nlohmann::json();
  if (kind != nlohmann::json("flag") && kind != nlohmann::json("cloth"))
    throw std::runtime_error(dir + "/index.json: field 'kind' is " + kind.dump() +
                             ", expected \"flag\" or \"cloth\" (only simulated datasets are re-indexed)");
  const IndexLock lock(dir);
  RemoveIndexTemporariesOfStoppedRuns(dir);
  std::vector<std::string> incomplete, unlabelled;
  const nlohmann::json count_before = index.value("count", nlohmann::json());
  index = BuildIndex(dir, index, progress, &incomplete, nullptr, &unlabelled);
  SayIncomplete("make-dataset --reindex", incomplete);
  // Left out without a word before: frames copied in without their label, or a folder that is no
  // example. (A generating run does not say it: other shards' examples are being written.)
  if (!unlabelled.empty())
    std::fprintf(stderr, "make-dataset --reindex: %zu folder%s without a label.json left out of the index: %s (not "
                 "an example, or one a run is still writing)\n",
                 unlabelled.size(), unlabelled.size() == 1 ? "" : "s", FirstNames(unlabelled).c_str());
  if (index.value("count", nlohmann::json()) != count_before)
    std::fprintf(stderr, "make-dataset --reindex: the header's count raised from %s to %s, the simulations the folder "
                 "holds (a larger run's, stopped before it rewrote the header, or copied in)\n",
                 count_before.dump().c_str(), index.value("count", nlohmann::json()).dump().c_str());
  // The header's "tracks" says every example has its tracks.json: not when a merged shard was made
  // without them (the claim was kept, and training with --aux-tracks failed on the first such).
  if (index.contains("dataset") && index["dataset"].is_object() && index["dataset"].contains("tracks")) {
    const nlohmann::json grid = index["dataset"]["tracks"];
    const TrackGrid tracks{grid.is_array() && grid.size() == 2 && grid[0].is_number_integer() ? grid[0].get<int>() : 0,
                           grid.is_array() && grid.size() == 2 && grid[1].is_number_integer() ? grid[1].get<int>() : 0};
    std::fprintf(stderr, "make-dataset --reindex: checking %zu examples' tracks.json (the header claims %dx%d)\n",
                 index["clips"].size(), tracks.cols, tracks.rows);
    int64_t without = 0;
    for (const auto& clip : index["clips"])
      if (!TracksHaveWorld(fs::path(dir) / clip["name"].get<std::string>() / "tracks.json", tracks)) ++without;
    if (without > 0) {
      index["dataset"].erase("tracks");
      std::fprintf(stderr,
                   "make-dataset --reindex: %lld examples have no tracks.json of the header's grid %s: the header no "
                   "longer claims tracks (give them theirs with --add-tracks --tracks %dx%d)\n",
                   static_cast<long long>(without), grid.dump().c_str(), tracks.cols, tracks.rows);
    }
  }
  WriteIndex(dir, index);
  if (contact_sheet) WriteContactSheet(dir, index, (fs::path(dir) / "contact_sheet.png").string());
  return static_cast<int64_t>(index["clips"].size());
}

DatasetSummary GenerateDataset(const DatasetOptions& o, const DatasetProgressCallback& progress,
                               const std::function<void(int, int)>& index_progress) {
  ValidateDatasetOptions(o);
  const auto start = Clock::now();
  const Prepared prep = Prepare(o);
  nlohmann::json settings = DatasetSettingsJson(o, FabricNames(prep.fabrics), prep.scene_files, prep.background_files);
  const nlohmann::json existing = ReadIndex(o.out);
  if (o.add_tracks && existing.is_null())
    throw std::runtime_error("--add-tracks: " + (fs::path(o.out) / "index.json").string() +
                             " not found: tracks are added to a dataset made before");
  if (!existing.is_null()) CheckIndexIsThisKind(o.out, existing, o);
  fs::create_directories(o.out);
  if (o.add_tracks) {
    // The examples were made without tracks: every other setting must be theirs. Their frames
    // stay as the generator that made them rendered them (nothing is written into them; the
    // replay check compares the last frame within a tolerance), so the folder keeps its
    // generator_version rather than being refused for it.
    if (!existing.is_null() && existing.contains("dataset") && existing["dataset"].contains("generator_version"))
      settings["generator_version"] = existing["dataset"]["generator_version"];
    CheckCompatible(o.out, settings, "tracks");
  } else {
    CheckCompatible(o.out, settings);
  }

  DatasetSummary summary;
  summary.jobs = o.jobs > 0 ? o.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));

  // Left-overs of a killed run of this shard: its temporary folders whose process has stopped
  // (other shards' may be in use on other machines, and a run of another split into this folder
  // may be writing this shard's: its folders were removed under it and its rename failed).
  for (const auto& e : fs::directory_iterator(o.out)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name[0] != '.' || name.find(".tmp-") == std::string::npos) continue;
    const int64_t i = IndexOfName(name, o.kind);
    if (i >= 0 && i % o.shards == o.shard && IsTemporaryOfStoppedProcess(name)) fs::remove_all(e.path());
  }


  // This shard's simulations that still miss a view (--add-tracks: a view's tracks).
  auto has = [&](int64_t i, int v, const char* file) {
    return fs::exists(fs::path(o.out) / ExampleName(o.kind, i, v) / file);
  };
  auto view_done = [&](int64_t i, int v) {
    if (!o.add_tracks)
      return has(i, v, "label.json") &&
             FramesPresent(fs::path(o.out) / ExampleName(o.kind, i, v), o.frames, FramePattern(o.frame_ext));
    return !has(i, v, "label.json") ||
           TracksHaveWorld(fs::path(o.out) / ExampleName(o.kind, i, v) / "tracks.json", *o.tracks);
  };
  std::vector<int64_t> todo;
  for (int64_t i = o.shard; i < o.count; i += o.shards) {
    if (!o.split.empty() && SplitOf(SimulationSeed(o.seed, i), o.val_fraction, o.test_fraction) != o.split)
      continue;
    ++summary.assigned;
    bool complete = true;
    for (int v = 0; v < o.views && complete; ++v) complete = view_done(i, v);
    for (int v = 0; v < o.views; ++v)  // every finished view is this run's, complete simulation or not
      if (has(i, v, "label.json")) CheckExampleLabel(o.out, i, v, o, prep);
    if (complete) ++summary.skipped;
    else todo.push_back(i);
  }

  // A new folder gets its index's header before the first simulation (after the examples found
  // were checked: a refused run left its own settings there): a run killed midway (or
  // stopped by a time limit) leaves a folder that says what it is, so a rerun with other settings
  // is still refused, and `make-dataset --reindex` lists the examples it finished. (A folder that
  // has an index keeps it until the end, which rebuilds it from the folders present.)
  {
    const IndexLock lock(o.out);
    if (ReadIndex(o.out).is_null()) WriteIndex(o.out, IndexHeader(o, settings));
  }

  std::mutex mutex;  // guards summary and progress
  DatasetProgress state;
  state.total = static_cast<int64_t>(todo.size());
  const double frame_time = 1.0 / o.fps;
  const int first_frame = static_cast<int>(std::lround(o.warmup / frame_time));

  auto work = [&](int64_t i) {
    double sim_s = 0, render_s = 0, write_s = 0;
    int written = 0;
    std::string last, error;
    try {
      const SimulationSample s = SampleOf(o, prep, i);
      auto t0 = Clock::now();
      const sim::SceneSetup setup = SetupFor(prep, s, o.kind);
      // The warm-up is the simulator's own (the same steps, wind and gust horizon as simulating
      // it as frames, so the same frames): kept as frames, --warmup 3600 --fps 1000 held 3.6
      // million of them, some 18 GB a job, only to drop them.
      sim::SimulateOptions so;
      so.warmup = first_frame * frame_time;
      so.duration = (o.frames - 1) * frame_time;
      so.seed = s.seed;
      const sim::Trajectory traj = sim::SimulateTrajectory(setup, s.theta, so);
      CheckFinite(traj);
      const ClothAnimation anim = AnimationFromTrajectory(traj, 0, o.frames);
      sim_s += Seconds(t0);
      ClipInfo info;
      info.dataset = render::SceneKindName(o.kind);
      info.dataset_seed = o.seed;
      info.views = o.views;
      info.split = SplitOf(s.seed, o.val_fraction, o.test_fraction);
      info.num_frames = o.frames;
      info.frame_rate = o.fps;
      info.frame_ext = o.frame_ext;
      info.scene = prep.scene_name;
      info.max_edge = setup.cloths[0].max_edge;
      info.vertices = traj.num_vertices();
      info.faces = traj.num_faces();
      info.time_step = setup.cloths[0].options.dt;
      info.warmup = first_frame * frame_time;
      for (int v = 0; v < o.views; ++v) {
        const std::string name = ExampleName(o.kind, i, v);
        if (view_done(i, v)) continue;
        t0 = Clock::now();
        const render::RenderParams zeta = ViewOf(o, prep, s, v);
        render::RenderOptions ro;
        ro.threads = 1;  // parallel over simulations instead
        render::Renderer renderer(zeta, ro);
        const nlohmann::json tracks = o.tracks ? TracksJson(ProjectTracks(anim, zeta, *o.tracks, o.frames)) : nullptr;
        if (o.add_tracks) {
          const int last_frame = o.frames - 1;
          CheckReplay(fs::path(o.out) / name, last_frame, o.frame_ext,
                      RenderAnimation(&renderer, anim, last_frame / o.fps, 1, o.fps)[0]);
          render_s += Seconds(t0);
          t0 = Clock::now();
          sim::WriteFileAtomically((fs::path(o.out) / name / "tracks.json").string(), tracks.dump() + "\n");
        } else {
          const std::vector<cv::Mat> images = RenderAnimation(&renderer, anim, 0.0, o.frames, o.fps);
          render_s += Seconds(t0);
          t0 = Clock::now();
          info.view = v;
          WriteExample(o.out, name, images, SimExampleLabel(name, s, zeta, info), tracks, o);
        }
        write_s += Seconds(t0);
        ++written;
        last = name;
      }
    } catch (const std::exception& e) {
      error = render::SceneKindName(o.kind) + " simulation " + std::to_string(i) + ": " + e.what();
    }
    std::lock_guard<std::mutex> lock(mutex);
    summary.simulate_seconds += sim_s;
    summary.render_seconds += render_s;
    summary.write_seconds += write_s;
    summary.examples_written += written;
    ++summary.simulated;
    ++state.done;
    if (!error.empty()) {
      ++summary.failed;
      ++state.failed;
      summary.errors.push_back(error);
      state.last = "FAILED " + error;
    } else {
      state.last = last;
    }
    if (progress) progress(state);
  };

  if (!todo.empty()) {
    // The bar's pace is measured from its first report: here, the start of the work. From the
    // first finished simulation, --jobs 16 finishing 16 at once read as 15 in a few seconds.
    if (progress) progress(state);
    tbb::task_arena arena(summary.jobs);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, todo.size(), 1),
                        [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t k = r.begin(); k < r.end(); ++k) work(todo[k]);
                        },
                        tbb::simple_partitioner());
    });
  }
  std::sort(summary.errors.begin(), summary.errors.end());

  // Every run rebuilds the index from the folders present: shards and resumed runs converge.
  const IndexLock lock(o.out);
  RemoveIndexTemporariesOfStoppedRuns(o.out);
  std::vector<std::string> incomplete, beyond;
  nlohmann::json index = BuildIndex(o.out, IndexHeader(o, settings), index_progress, &incomplete, &beyond);
  SayIncomplete("make-dataset", incomplete);
  if (!beyond.empty())
    std::fprintf(stderr, "make-dataset: %zu example folder%s of simulations past --count %lld left out of the index "
                 "(the first: %s; a larger run's: `--reindex` lists them under a raised count)\n",
                 beyond.size(), beyond.size() == 1 ? "" : "s", static_cast<long long>(o.count), beyond.front().c_str());
  if (o.add_tracks) {
    // The header's "tracks" says every example has its tracks.json: not while a replay failed or
    // another split still waits for its tracks (a later --add-tracks run completes it; a run with
    // --tracks alone is then refused, pointing at --add-tracks, instead of leaving those without).
    // Counted as the run counts them done: a tracks.json without the points' positions (an old
    // one whose replay failed) is not the grid's either.
    for (const auto& clip : index["clips"])
      if (!TracksHaveWorld(fs::path(o.out) / clip.value("name", std::string()) / "tracks.json", *o.tracks))
        ++summary.examples_without_tracks;
    if (summary.examples_without_tracks > 0) index["dataset"].erase("tracks");
  }
  WriteIndex(o.out, index);
  summary.examples_in_index = static_cast<int64_t>(index["clips"].size());
  summary.index_path = (fs::path(o.out) / "index.json").string();
  if (o.contact_sheet) {
    const std::string sheet = (fs::path(o.out) / "contact_sheet.png").string();
    if (WriteContactSheet(o.out, index, sheet)) summary.contact_sheet_path = sheet;
  }
  summary.wall_seconds = Seconds(start);
  return summary;
}

}  // namespace clothwind::data
