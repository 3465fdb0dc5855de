#include "data/dataset_generator.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <sstream>

#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "data/contact_sheet.h"
#include "data/dataset_index.h"
#include "data/paths.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"
#include "sim/simulate.h"

namespace clothwind::data {
namespace {

namespace fs = std::filesystem;

// A tiny FlagSim: coarse mesh, short simulations, small frames (a few seconds in all).
DatasetOptions Tiny(const std::string& out, uint64_t seed = 1) {
  DatasetOptions o;
  o.kind = render::SceneKind::kFlag;
  o.count = 3;
  o.views = 1;
  o.out = out;
  o.seed = seed;
  o.jobs = 2;
  o.max_edge = 1.0;
  o.warmup = 0.4;
  o.frames = 6;
  o.samples = 1;
  o.size = 64;
  return o;
}

std::string Bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Every file under dir (relative path -> bytes).
std::map<std::string, std::string> Files(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = Bytes(e.path());
  return files;
}

class DatasetGeneratorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("clothwind_data_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    reference_ = GenerateDataset(Tiny((root_ / "reference").string()));
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static fs::path Ref() { return root_ / "reference"; }

  static fs::path root_;
  static DatasetSummary reference_;
};
fs::path DatasetGeneratorTest::root_;
DatasetSummary DatasetGeneratorTest::reference_;

TEST_F(DatasetGeneratorTest, IndexAndLabelsRoundTrip) {
  ASSERT_TRUE(reference_.errors.empty()) << reference_.errors[0];
  EXPECT_EQ(reference_.assigned, 3);
  EXPECT_EQ(reference_.examples_written, 3);
  const nlohmann::json index = ReadIndex(Ref().string());
  ASSERT_FALSE(index.is_null());
  EXPECT_EQ(index["format"], "clothwind-dataset");
  EXPECT_EQ(index["version"], 1);
  EXPECT_EQ(index["kind"], "flag");
  ASSERT_EQ(index["clips"].size(), 3u);
  const sim::SceneSetup setup = sim::BuildScene(sim::LoadScene(DefaultScenePath(render::SceneKind::kFlag)));
  for (int i = 0; i < 3; ++i) {
    const auto& entry = index["clips"][i];
    const std::string name = ExampleName(render::SceneKind::kFlag, i, 0);
    EXPECT_EQ(entry["name"], name);
    const nlohmann::json label = ReadLabel((Ref() / name / "label.json").string());
    // The label carries what the sampler drew for this index, exactly.
    const SimulationSample s =
        SampleFlagSimulation(sim::SceneTheta(setup), 1, i, DefaultRanges(render::SceneKind::kFlag));
    const sim::Theta theta = LabelTheta(label);
    for (int k = 0; k < sim::kNumParameters; ++k) EXPECT_EQ(theta[k], s.theta[k]) << k;
    EXPECT_EQ(label["wind_speed"].get<double>(), s.theta[16]);
    EXPECT_EQ(entry["wind_speed"], label["wind_speed"]);
    EXPECT_EQ(label["seed"].get<uint64_t>(), s.seed);
    EXPECT_EQ(label["kind"], "sim");
    EXPECT_EQ(label["encoding"], "rgb8");
    EXPECT_EQ(label["frame_rate"], 25.0);
    EXPECT_EQ(label["num_frames"], 6);
    EXPECT_EQ(label["theta_names"].size(), 17u);
    EXPECT_EQ(label["generator"]["name"], kGeneratorName);
    EXPECT_EQ(label["split"], SplitOf(s.seed, 0.1, 0.2));
    EXPECT_EQ(entry["split"], label["split"]);
    render::RenderParams zeta = SampleView(render::SceneKind::kFlag, s.seed, 0, 1);
    zeta.samples = 1;
    zeta.width = zeta.height = 64;
    EXPECT_EQ(render::ToJson(LabelZeta(label)), render::ToJson(zeta));
    for (int f = 0; f < 6; ++f) {
      char file[16];
      std::snprintf(file, sizeof(file), "%03d.jpg", f);
      const cv::Mat img = cv::imread((Ref() / name / file).string(), cv::IMREAD_UNCHANGED);
      ASSERT_FALSE(img.empty()) << file;
      EXPECT_EQ(img.cols, 64);
      EXPECT_EQ(img.rows, 64);
      EXPECT_EQ(img.channels(), 3);
    }
    EXPECT_FALSE(fs::exists(Ref() / name / "006.jpg"));
  }
  EXPECT_TRUE(fs::exists(Ref() / "contact_sheet.png"));
  // No temporary folder is left behind (the index's lock file stays: removing it would race a
  // shard about to lock it).
  for (const auto& e : fs::directory_iterator(Ref())) {
    if (e.path().filename() == ".index.lock") continue;
    EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
  }
}

TEST_F(DatasetGeneratorTest, DeterministicBySeed) {
  const fs::path again = root_ / "again", other = root_ / "other";
  DatasetOptions o = Tiny(again.string());
  o.jobs = 1;  // a different thread count must not matter
  GenerateDataset(o);
  EXPECT_EQ(Files(again), Files(Ref()));
  GenerateDataset(Tiny(other.string(), 2));
  const auto a = Files(Ref()), b = Files(other);
  EXPECT_NE(a.at("flag-000000-v0/label.json"), b.at("flag-000000-v0/label.json"));
  EXPECT_NE(a.at("flag-000000-v0/003.jpg"), b.at("flag-000000-v0/003.jpg"));
}

TEST_F(DatasetGeneratorTest, ResumesAfterAKillWithoutRedoingFinishedExamples) {
  const fs::path dir = root_ / "resume";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  // The state a kill leaves: example 1 was being written (a temporary folder with a partial
  // frame, no folder under its name); 0 and 2 were finished long ago.
  fs::remove_all(dir / "flag-000001-v0");
  // A pid above any pid_max (at most 2^22): 999999 can be a live process on a host of 4 million.
  const fs::path stale = dir / ".flag-000001-v0.tmp-999999999-7";
  fs::create_directories(stale);
  std::ofstream(stale / "000.jpg") << "partial";
  // And what a kill while the index or the contact sheet was written leaves (never cleared).
  std::ofstream(dir / "index.json.tmp-999999999-4") << "{";
  std::ofstream(dir / "contact_sheet.png.tmp-999999999-5") << "PNG";
  const auto old_time = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (const char* name : {"flag-000000-v0", "flag-000002-v0"}) {
    fs::last_write_time(dir / name / "label.json", old_time);
    fs::last_write_time(dir / name / "003.jpg", old_time);
  }
  const DatasetSummary s = GenerateDataset(Tiny(dir.string()));
  EXPECT_EQ(s.skipped, 2);
  EXPECT_EQ(s.simulated, 1);
  EXPECT_EQ(s.examples_written, 1);
  EXPECT_FALSE(fs::exists(stale));
  for (const char* name : {"flag-000000-v0", "flag-000002-v0"}) {
    EXPECT_EQ(fs::last_write_time(dir / name / "label.json"), old_time) << name;
    EXPECT_EQ(fs::last_write_time(dir / name / "003.jpg"), old_time) << name;
  }
  // The redone example is the one a single uninterrupted run makes, and so is the index.
  EXPECT_EQ(Files(dir), Files(Ref()));
  // A second resume has nothing to do.
  const DatasetSummary again = GenerateDataset(Tiny(dir.string()));
  EXPECT_EQ(again.skipped, 3);
  EXPECT_EQ(again.simulated, 0);
}

TEST_F(DatasetGeneratorTest, BlownUpSimulationIsRecordedAsFailedAndWritesNothing) {
  // A 1e5 m/s wind tears the flag apart in the first step: the simulator's blow-up check must
  // stop each simulation (no hang, no half-written example) and the run must report them.
  DatasetOptions o = Tiny((root_ / "blown_up").string());
  o.count = 2;
  SamplingRanges r = DefaultRanges(render::SceneKind::kFlag);
  r.wind_min = r.wind_max = 1e5;
  o.ranges = r;
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_EQ(s.simulated, 2);
  EXPECT_EQ(s.failed, 2);
  EXPECT_EQ(s.examples_written, 0);
  ASSERT_EQ(s.errors.size(), 2u);
  for (const std::string& e : s.errors) EXPECT_NE(e.find("blew up at t = "), std::string::npos) << e;
  for (const auto& entry : fs::directory_iterator(root_ / "blown_up"))
    EXPECT_FALSE(entry.is_directory()) << "example folder written: " << entry.path();
}

TEST_F(DatasetGeneratorTest, OneSplitIsTheWholeDatasetsExamplesOfThatSplitAndResumesToIt) {
  // The reference's simulations fall into more than one split, so one split is a proper part.
  const nlohmann::json ref_index = ReadIndex(Ref().string());
  std::map<std::string, int> per_split;
  for (const auto& clip : ref_index["clips"]) ++per_split[clip["split"].get<std::string>()];
  ASSERT_GE(per_split.size(), 2u) << ref_index["clips"].dump();
  const std::string split = ref_index["clips"][0]["split"];

  const fs::path dir = root_ / ("only-" + split);
  DatasetOptions o = Tiny(dir.string());
  o.split = split;
  const DatasetSummary s = GenerateDataset(o);
  ASSERT_TRUE(s.errors.empty()) << s.errors[0];
  EXPECT_EQ(s.assigned, per_split[split]);
  EXPECT_EQ(s.examples_written, per_split[split]);
  // Its index lists the reference's examples of that split, and each is the reference's byte for byte.
  const nlohmann::json index = ReadIndex(dir.string());
  nlohmann::json expected = nlohmann::json::array();
  for (const auto& clip : ref_index["clips"])
    if (clip["split"] == split) expected.push_back(clip);
  EXPECT_EQ(index["clips"], expected);
  for (const auto& clip : expected) {
    const std::string name = clip["name"];
    for (const auto& [file, bytes] : Files(Ref() / name)) EXPECT_EQ(Bytes(dir / name / file), bytes) << name << "/" << file;
  }
  // A run without --split completes it into the whole dataset, redoing nothing.
  const DatasetSummary rest = GenerateDataset(Tiny(dir.string()));
  EXPECT_EQ(rest.skipped, per_split[split]);
  EXPECT_EQ(rest.examples_written, 3 - per_split[split]);
  EXPECT_EQ(Files(dir), Files(Ref()));
  // A split that is not one is refused by name.
  o.split = "validation";
  try {
    GenerateDataset(o);
    ADD_FAILURE() << "--split validation was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--split must be train, val or test"), std::string::npos) << e.what();
  }
}

TEST_F(DatasetGeneratorTest, ShardsTogetherEqualOneRun) {
  const fs::path dir = root_ / "shards";
  int64_t total = 0;
  for (int k : {2, 0, 1}) {  // any order
    DatasetOptions o = Tiny(dir.string());
    o.shard = k;
    o.shards = 3;
    o.jobs = 1;
    const DatasetSummary s = GenerateDataset(o);
    EXPECT_EQ(s.assigned, 1);
    total += s.examples_written;
  }
  EXPECT_EQ(total, 3);
  EXPECT_EQ(Files(dir), Files(Ref()));  // frames, labels, index.json and contact sheet
  // Two shards of two: shard 0 does 0 and 2, shard 1 does 1.
  DatasetOptions o = Tiny((root_ / "shards2").string());
  o.shards = 2;
  o.shard = 1;
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_EQ(s.assigned, 1);
  EXPECT_TRUE(fs::exists(root_ / "shards2" / "flag-000001-v0"));
  EXPECT_FALSE(fs::exists(root_ / "shards2" / "flag-000000-v0"));
}

TEST_F(DatasetGeneratorTest, RefusesToMixSettingsInOneFolder) {
  const fs::path dir = root_ / "mixed";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  DatasetOptions o = Tiny(dir.string(), 5);
  try {
    GenerateDataset(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dataset.seed"), std::string::npos) << e.what();
  }
  // A larger count extends the dataset instead.
  o = Tiny(dir.string());
  o.count = 4;
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_EQ(s.skipped, 3);
  EXPECT_EQ(s.examples_in_index, 4);
}

// What the runtime_error of GenerateDataset(o) says ("" when it ran).
std::string GenerateError(const DatasetOptions& o) {
  try {
    GenerateDataset(o);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST_F(DatasetGeneratorTest, AResumeWithoutAnIndexChecksTheExamplesItFinds) {
  // docs/datasets.md's recipe copies another dataset's examples and drops its index: the labels
  // are then all that says how the examples were made (they were counted complete unchecked).
  const fs::path dir = root_ / "no-index";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  fs::remove(dir / "index.json");
  DatasetOptions o = Tiny(dir.string());
  o.frames = 5;
  std::string error = GenerateError(o);
  EXPECT_NE(error.find((dir / "flag-000000-v0" / "label.json").string() + ": field 'num_frames' is 6, this run makes 5"),
            std::string::npos)
      << error;
  o = Tiny(dir.string(), 2);
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'dataset_seed' is 1, this run makes 2"), std::string::npos) << error;
  o = Tiny(dir.string());
  o.warmup = 0.8;
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'simulation_settings.warmup' is 0.4"), std::string::npos) << error;
  o = Tiny(dir.string());
  o.max_edge = 0.5;  // another mesh
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'simulation_settings.vertices'"), std::string::npos) << error;
  // What was drawn for each example, and how many views and which split, were not compared: the
  // copies were counted complete under a header that claimed this run's settings.
  o = Tiny(dir.string());
  o.views = 2;  // over a copy of one view
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'views' is 1, this run makes 2"), std::string::npos) << error;
  o = Tiny(dir.string());
  SamplingRanges narrow = DefaultRanges(render::SceneKind::kFlag);
  narrow.wind_max = 5;  // over 0-10 m/s
  o.ranges = narrow;
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'theta' is"), std::string::npos) << error;
  o = Tiny(dir.string());
  SamplingRanges high = DefaultRanges(render::SceneKind::kFlag);
  high.camera.height_min = 5.1, high.camera.height_max = 6.1;  // other cameras
  o.ranges = high;
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'zeta' is"), std::string::npos) << error;
  o = Tiny(dir.string());
  o.val_fraction = 0, o.test_fraction = 1;  // every simulation in test: one of them was not
  error = GenerateError(o);
  EXPECT_NE(error.find("field 'split' is \"train\", this run makes \"test\""), std::string::npos) << error;
  o = Tiny(dir.string());
  o.tracks = TrackGrid{4, 3};
  error = GenerateError(o);
  EXPECT_NE(error.find("flag-000000-v0 has no tracks.json, and this run makes tracks"), std::string::npos) << error;
  {  // another generator's frames
    const fs::path file = dir / "flag-000001-v0" / "label.json";
    const std::string bytes = Bytes(file);
    nlohmann::json label = nlohmann::json::parse(bytes);
    label["generator"]["version"] = kGeneratorVersion - 1;
    std::ofstream(file) << label.dump(2) << "\n";
    error = GenerateError(Tiny(dir.string()));
    EXPECT_NE(error.find("field 'generator.version' is " + std::to_string(kGeneratorVersion - 1) +
                         ", this run makes " + std::to_string(kGeneratorVersion)),
              std::string::npos)
        << error;
    std::ofstream(file, std::ios::binary) << bytes;
  }
  EXPECT_FALSE(fs::exists(dir / "index.json"));  // the refused runs wrote no header of theirs
  // The same settings resume it, with nothing to do, and the index is the reference's again.
  const DatasetSummary s = GenerateDataset(Tiny(dir.string()));
  EXPECT_EQ(s.skipped, 3);
  EXPECT_EQ(Files(dir), Files(Ref()));
}

TEST_F(DatasetGeneratorTest, AnIndexOfAnotherKindOrALargerCountIsRefused) {
  const fs::path dir = root_ / "other-index";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  const nlohmann::json index = nlohmann::json::parse(Bytes(dir / "index.json"));
  auto write = [&](const nlohmann::json& j) { std::ofstream(dir / "index.json") << j.dump(2) << "\n"; };
  nlohmann::json recorded = index;  // a recording's index: no "dataset", its own kind
  recorded.erase("dataset");
  recorded["kind"] = "real";
  write(recorded);
  EXPECT_NE(GenerateError(Tiny(dir.string())).find("index.json: no field 'dataset'"), std::string::npos);
  nlohmann::json cloth = index;
  cloth["kind"] = "cloth";
  write(cloth);
  EXPECT_NE(GenerateError(Tiny(dir.string())).find("field 'kind' is \"cloth\", this run makes \"flag\""),
            std::string::npos);
  write(index);
  DatasetOptions fewer = Tiny(dir.string());
  fewer.count = 2;
  EXPECT_NE(GenerateError(fewer).find("field 'count' is 3 but this run asks for 2"), std::string::npos)
      << GenerateError(fewer);
  EXPECT_EQ(nlohmann::json::parse(Bytes(dir / "index.json")), index);
  // A folder an older generator made (its frames render otherwise): refused, saying so.
  nlohmann::json older = index;
  older["dataset"]["generator_version"] = kGeneratorVersion - 1;
  write(older);
  const std::string error = GenerateError(Tiny(dir.string()));
  EXPECT_NE(error.find("field 'dataset.generator_version' is " + std::to_string(kGeneratorVersion - 1)),
            std::string::npos) << error;
  EXPECT_NE(error.find("an older make-dataset made those frames"), std::string::npos) << error;
}

// A scene whose flag is another size (here 6 m x 4 m): ζ's pole and camera aim follow it (they
// assumed the usual 3 m x 2 m flag, which then flew beside its pole), and the usual flag's ζ is
// what it was (the reference's labels are made by the same code: 3 m, aspect 1.5).
TEST_F(DatasetGeneratorTest, AFlagOfAnotherSizeGetsZetaOfItsSize) {
  const fs::path config = fs::path(DefaultScenePath(render::SceneKind::kFlag)).parent_path().parent_path();
  const fs::path copy = root_ / "big-scene";
  for (const char* f : {"scenes/flag.json", "meshes/flag.obj", "materials/camel-ponte-roma.json"}) {
    fs::create_directories((copy / f).parent_path());
    fs::copy_file(config / f, copy / f);
  }
  {  // every vertex twice as far from the origin
    std::ifstream in(config / "meshes/flag.obj");
    std::ofstream out(copy / "meshes/flag.obj");
    for (std::string line; std::getline(in, line);) {
      double x, y, z;
      if (line.rfind("v ", 0) == 0 && std::sscanf(line.c_str(), "v %lf %lf %lf", &x, &y, &z) == 3)
        out << "v " << 2 * x << " " << 2 * y << " " << 2 * z << "\n";
      else
        out << line << "\n";
    }
  }
  DatasetOptions o = Tiny((root_ / "big-flag").string());
  o.count = 1;
  o.max_edge = 2.0;
  o.scene = (copy / "scenes/flag.json").string();
  ASSERT_EQ(GenerateError(o), "");
  const nlohmann::json zeta = ReadLabel((root_ / "big-flag" / "flag-000000-v0" / "label.json").string())["zeta"];
  EXPECT_NEAR(zeta["mesh_width"].get<double>(), 6.0, 1e-6) << zeta;
  EXPECT_NEAR(zeta["mesh_aspect_ratio"].get<double>(), 1.5, 1e-6) << zeta;
  const nlohmann::json usual = ReadLabel((Ref() / "flag-000000-v0" / "label.json").string())["zeta"];
  EXPECT_EQ(usual["mesh_width"], 3.0);
  EXPECT_EQ(usual["mesh_aspect_ratio"], 1.5);
}

TEST_F(DatasetGeneratorTest, AnEditedSceneIsNotMixedIn) {
  // A copy of the flag scene's files, laid out as config/ is.
  const fs::path config = fs::path(DefaultScenePath(render::SceneKind::kFlag)).parent_path().parent_path();
  const fs::path copy = root_ / "scene-copy";
  for (const char* f : {"scenes/flag.json", "meshes/flag.obj", "materials/camel-ponte-roma.json"}) {
    fs::create_directories((copy / f).parent_path());
    fs::copy_file(config / f, copy / f);
  }
  const fs::path dir = root_ / "edited-scene";
  DatasetOptions o = Tiny(dir.string());
  o.count = 1;
  o.scene = (copy / "scenes/flag.json").string();
  ASSERT_EQ(GenerateError(o), "");
  const nlohmann::json header = nlohmann::json::parse(Bytes(dir / "index.json"))["dataset"];
  ASSERT_TRUE(header.contains("scene_files"));
  // The same files: the same fingerprint as the default scene's (the reference's header).
  EXPECT_EQ(header["scene_files"], nlohmann::json::parse(Bytes(Ref() / "index.json"))["dataset"]["scene_files"]);
  // The material file edited (any byte counts: here a comment; a density would change the flag).
  const std::string material = Bytes(copy / "materials/camel-ponte-roma.json") + "\n// edited\n";
  std::ofstream(copy / "materials/camel-ponte-roma.json") << material;
  o.count = 2;
  const std::string error = GenerateError(o);
  EXPECT_NE(error.find("field 'dataset.scene_files'"), std::string::npos) << error;
  EXPECT_NE(error.find("a mesh or a material file changed"), std::string::npos) << error;
  // A header made before the fingerprint was recorded is taken as it is.
  nlohmann::json index = nlohmann::json::parse(Bytes(dir / "index.json"));
  index["dataset"].erase("scene_files");
  std::ofstream(dir / "index.json") << index.dump(2) << "\n";
  EXPECT_EQ(GenerateError(o), "");
  EXPECT_TRUE(nlohmann::json::parse(Bytes(dir / "index.json"))["dataset"].contains("scene_files"));
}

// Background photos are named by file name in the settings; other photos of the same names (a
// resume, or a shard on a machine whose folder differs) are refused by their bytes, not mixed in.
TEST_F(DatasetGeneratorTest, OtherBackgroundPhotosOfTheSameNamesAreNotMixedIn) {
  const fs::path red = root_ / "photos-red", blue = root_ / "photos-blue";
  for (const auto& [folder, colour] : {std::pair{red, cv::Scalar(0, 0, 255)}, std::pair{blue, cv::Scalar(255, 0, 0)}}) {
    fs::create_directories(folder);
    ASSERT_TRUE(cv::imwrite((folder / "p.png").string(), cv::Mat(48, 64, CV_8UC3, colour)));
  }
  const fs::path dir = root_ / "photos";
  DatasetOptions o = Tiny(dir.string());
  o.count = 1;
  o.background_images = {(red / "p.png").string()};
  ASSERT_EQ(GenerateError(o), "");
  const nlohmann::json header = nlohmann::json::parse(Bytes(dir / "index.json"))["dataset"];
  ASSERT_TRUE(header.contains("background_files")) << header.dump();
  o.count = 2;
  o.background_images = {(blue / "p.png").string()};
  const std::string error = GenerateError(o);
  EXPECT_NE(error.find("field 'dataset.background_files'"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(dir / "flag-000001-v0"));
  // The same photos again resume; a header made before the fingerprint is taken as it is.
  o.background_images = {(red / "p.png").string()};
  nlohmann::json index = nlohmann::json::parse(Bytes(dir / "index.json"));
  index["dataset"].erase("background_files");
  std::ofstream(dir / "index.json") << index.dump(2) << "\n";
  EXPECT_EQ(GenerateError(o), "");
  EXPECT_TRUE(fs::exists(dir / "flag-000001-v0"));
}

TEST_F(DatasetGeneratorTest, ALiveRunsTemporaryFolderIsLeftAlone) {
  // A run of another split into the same folder may be writing this shard's simulations: its
  // folders were removed under it (its rename then failed). Only a stopped process's go.
  const fs::path dir = root_ / "live-temporary";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  const fs::path live = dir / (".flag-000001-v0.tmp-" + std::to_string(::getpid()) + "-3");
  const fs::path stopped = dir / ".flag-000001-v0.tmp-999999999-3";
  for (const auto& t : {live, stopped}) {
    fs::create_directories(t);
    std::ofstream(t / "000.jpg") << "partial";
  }
  const DatasetSummary s = GenerateDataset(Tiny(dir.string()));
  EXPECT_EQ(s.skipped, 3);
  EXPECT_TRUE(fs::exists(live / "000.jpg"));
  EXPECT_FALSE(fs::exists(stopped));
}

TEST_F(DatasetGeneratorTest, AnExampleFolderWithoutItsLabelIsMadeAgain) {
  // An interrupted copy: the folder is there, its label (written last) is not. The rename onto
  // it failed ("Directory not empty") at every resume.
  const fs::path dir = root_ / "unfinished-copy";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  fs::remove(dir / "flag-000001-v0" / "label.json");
  fs::remove(dir / "flag-000001-v0" / "005.jpg");
  // A copy that went in the folder's hashed order: the label came, a frame did not. It was counted
  // complete and indexed.
  fs::remove(dir / "flag-000002-v0" / "003.jpg");
  // The file being copied when the copy stopped: there, but cut short (each format's ending, and
  // an empty file: FrameFileWholeTest). It was counted complete and indexed, and readers failed on
  // it later.
  fs::resize_file(dir / "flag-000000-v0" / "004.jpg", 100);
  const DatasetSummary s = GenerateDataset(Tiny(dir.string()));
  ASSERT_TRUE(s.errors.empty()) << s.errors[0];
  EXPECT_EQ(s.examples_written, 3);
  EXPECT_EQ(Files(dir), Files(Ref()));
}

// A copy of a dataset with tracks that stopped before an example's frames and tracks.json came:
// the example is made again (the missing tracks.json was refused first, pointing at --add-tracks,
// whose replay then lacked the last frame).
TEST_F(DatasetGeneratorTest, AnUnfinishedCopyOfAnExampleWithTracksIsMadeAgain) {
  const fs::path dir = root_ / "unfinished-tracks";
  DatasetOptions o = Tiny(dir.string());
  o.count = 1;
  o.tracks = TrackGrid{4, 3};
  GenerateDataset(o);
  const std::map<std::string, std::string> whole = Files(dir);
  fs::remove(dir / "flag-000000-v0" / "tracks.json");
  fs::remove(dir / "flag-000000-v0" / "005.jpg");
  const DatasetSummary s = GenerateDataset(o);
  ASSERT_TRUE(s.errors.empty()) << s.errors[0];
  EXPECT_EQ(s.examples_written, 1);
  EXPECT_EQ(Files(dir), whole);
}

TEST_F(DatasetGeneratorTest, OtherCamerasAreRecordedAndNotMixedIn) {
  // Table 2's cameras leave the settings as they were before cameras were an option (so older
  // datasets resume); other ranges are recorded, and a resume with others is refused.
  DatasetOptions o = Tiny((root_ / "cameras").string());
  EXPECT_FALSE(DatasetSettingsJson(o, {})["ranges"].contains("camera"));
  SamplingRanges r = DefaultRanges(render::SceneKind::kFlag);
  r.camera.height_min = 5.1, r.camera.height_max = 6.1;
  o.ranges = r;
  const nlohmann::json camera = DatasetSettingsJson(o, {})["ranges"]["camera"];
  EXPECT_EQ(camera["height"], nlohmann::json::array({5.1, 6.1}));
  EXPECT_EQ(camera["radius"], nlohmann::json::array({4.0, 6.0}));
  EXPECT_EQ(camera["angle_max_deg"], 15.0);
  o.count = 1;
  EXPECT_EQ(GenerateDataset(o).examples_written, 1);
  const auto label = ReadLabel((root_ / "cameras" / "flag-000000-v0" / "label.json").string());
  const auto table = ReadLabel((Ref() / "flag-000000-v0" / "label.json").string());
  EXPECT_GE(label["zeta"]["camera_height"].get<double>(), 5.1);
  EXPECT_LE(label["zeta"]["camera_height"].get<double>(), 6.1);
  EXPECT_EQ(label["theta"], table["theta"]);
  EXPECT_EQ(label["zeta"]["texture_name"], table["zeta"]["texture_name"]);
  o.ranges.reset();
  try {
    GenerateDataset(o);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dataset.ranges"), std::string::npos) << e.what();
  }
}

TEST_F(DatasetGeneratorTest, ViewsRenderOneSimulationFromSeveralCameras) {
  DatasetOptions o = Tiny((root_ / "views").string());
  o.count = 1;
  o.views = 2;
  const DatasetSummary s = GenerateDataset(o);
  EXPECT_EQ(s.examples_written, 2);
  const auto a = ReadLabel((root_ / "views" / "flag-000000-v0" / "label.json").string());
  const auto b = ReadLabel((root_ / "views" / "flag-000000-v1" / "label.json").string());
  EXPECT_EQ(a["theta"], b["theta"]);
  EXPECT_EQ(a["split"], b["split"]);
  EXPECT_LT(a["zeta"]["camera_angle_deg"].get<double>(), 0.0);
  EXPECT_GE(b["zeta"]["camera_angle_deg"].get<double>(), 0.0);
  // View 0 of a 2-view dataset is not the frames of the 1-view one (another camera).
  EXPECT_NE(Bytes(root_ / "views" / "flag-000000-v0" / "003.jpg"),
            Bytes(Ref() / "flag-000000-v0" / "003.jpg"));
}

TEST_F(DatasetGeneratorTest, ClothSimUsesTheFabricsOfAFolder) {
  const fs::path materials = root_ / "materials";
  fs::create_directories(materials);
  const std::string base = (fs::path(ConfigDir()) / "materials" / "camel-ponte-roma.json").string();
  fs::copy_file(base, materials / "fabric-a.json");
  fs::copy_file(base, materials / "fabric-b.json");
  fs::copy_file(base, materials / "paper.json");  // excluded by default
  DatasetOptions o = Tiny((root_ / "cloth").string());
  o.kind = render::SceneKind::kCloth;
  o.materials_dir = materials.string();
  const DatasetSummary s = GenerateDataset(o);
  ASSERT_TRUE(s.errors.empty()) << s.errors[0];
  const nlohmann::json index = ReadIndex((root_ / "cloth").string());
  EXPECT_EQ(index["dataset"]["fabrics"], nlohmann::json({"fabric-a", "fabric-b"}));
  ASSERT_EQ(index["clips"].size(), 3u);
  for (const auto& c : index["clips"]) {
    const auto label = ReadLabel((root_ / "cloth" / c["name"].get<std::string>() / "label.json").string());
    EXPECT_EQ(label["dataset"], "cloth");
    EXPECT_GE(label["theta"][0].get<double>(), 0.1);
    EXPECT_LE(label["theta"][0].get<double>(), 0.4);
    EXPECT_EQ(label["wind_velocity"][2].get<double>(), 0.0);
    EXPECT_EQ(label["zeta"]["texture_kind"], "fabric");
    EXPECT_TRUE(label["fabric"] == "fabric-a" || label["fabric"] == "fabric-b") << label["fabric"];
  }
  // The drawn fabric reaches the simulation: the same sample with the fabric's stretching scaled
  // down makes other frames. (Labels could not tell: θ is drawn from the list of names, and
  // density and bending come from θ; the fabrics above are copies of one file.)
  std::ifstream base_in(base);
  nlohmann::json soft = nlohmann::json::parse(base_in, nullptr, true, /*ignore_comments=*/true);
  for (auto& row : soft["stretching"])
    for (auto& v : row) v = v.get<double>() * 0.05;
  std::string frames[2];
  for (int k = 0; k < 2; ++k) {
    const fs::path folder = root_ / ("one-fabric-" + std::to_string(k));
    fs::create_directories(folder);
    if (k == 0) fs::copy_file(base, folder / "fabric-a.json");
    else std::ofstream(folder / "fabric-a.json") << soft.dump(2);
    DatasetOptions one = Tiny((root_ / ("cloth-" + std::to_string(k))).string());
    one.kind = render::SceneKind::kCloth;
    one.materials_dir = folder.string();
    one.count = 1;
    ASSERT_TRUE(GenerateDataset(one).errors.empty());
    frames[k] = Bytes(root_ / ("cloth-" + std::to_string(k)) / "cloth-000000-v0" / "005.jpg");
  }
  EXPECT_FALSE(frames[0].empty());
  EXPECT_NE(frames[0], frames[1]) << "a fabric 20 times as stretchy left the frames unchanged";
}

TEST_F(DatasetGeneratorTest, ReindexMergesFoldersCopiedFromOtherMachines) {
  // Shard 1 of 2 ran here; shard 0's folders arrive later (copied from another machine).
  const fs::path dir = root_ / "merge";
  DatasetOptions o = Tiny(dir.string());
  o.shards = 2;
  o.shard = 1;
  std::vector<std::pair<int, int>> index_reports;
  GenerateDataset(o, {}, [&](int done, int total) { index_reports.emplace_back(done, total); });
  EXPECT_EQ(index_reports, (std::vector<std::pair<int, int>>{{0, 1}, {1, 1}}));
  EXPECT_EQ(ReadIndex(dir.string())["clips"].size(), 1u);
  for (const char* name : {"flag-000000-v0", "flag-000002-v0"})
    fs::copy(Ref() / name, dir / name, fs::copy_options::recursive);
  // Progress counts every label found, once each, ending at the total.
  std::vector<std::pair<int, int>> reports;
  EXPECT_EQ(ReindexDataset(dir.string(), true, [&](int done, int total) { reports.emplace_back(done, total); }), 3);
  EXPECT_EQ(reports, (std::vector<std::pair<int, int>>{{0, 3}, {1, 3}, {2, 3}, {3, 3}}));
  EXPECT_EQ(Files(dir), Files(Ref()));
  // A recorded dataset's index is the clip writer's: not rebuilt from labels.
  const fs::path real = root_ / "real";
  fs::create_directories(real);
  std::ofstream(real / "index.json") << R"({"format": "clothwind-dataset", "version": 1, "kind": "real", "clips": []})";
  EXPECT_THROW(ReindexDataset(real.string()), std::runtime_error);
  // A kind of another type is refused naming the index (it was a bare nlohmann type error).
  std::ofstream(real / "index.json") << R"({"format": "clothwind-dataset", "version": 1, "kind": 5, "clips": []})";
  try {
    ReindexDataset(real.string());
    ADD_FAILURE() << "kind 5 re-indexed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(real.string() + "/index.json: field 'kind' is 5"), std::string::npos) << e.what();
  }
}

// A run stopped after its first simulation (killed, or timed out) has already written the
// dataset's header: a rerun with other settings is refused, --reindex lists what was finished,
// and resuming ends where one uninterrupted run does.
TEST_F(DatasetGeneratorTest, AStoppedRunLeavesAnIndexThatReindexCompletes) {
  const fs::path dir = root_ / "stopped";
  DatasetOptions o = Tiny(dir.string());
  o.jobs = 1;
  bool had_index = false;
  const auto stop = [&](const DatasetProgress& p) {
    if (p.done == 0) return;  // the start
    had_index = fs::exists(dir / "index.json");
    throw std::runtime_error("stopped");
  };
  EXPECT_THROW(GenerateDataset(o, stop), std::runtime_error);
  EXPECT_TRUE(had_index);
  DatasetOptions other = o;
  other.size = 32;
  EXPECT_THROW(GenerateDataset(other), std::runtime_error);
  EXPECT_EQ(ReindexDataset(dir.string(), false), 1);
  const nlohmann::json index = ReadIndex(dir.string());
  EXPECT_EQ(index["dataset"], ReadIndex(Ref().string())["dataset"]);
  GenerateDataset(Tiny(dir.string()));
  EXPECT_EQ(Files(dir), Files(Ref()));
}

// A merge indexes other machines' shards under this folder's header: one made with other settings
// is refused naming its label and the field, and a header claiming tracks the examples lack stops
// claiming them (training with --aux-tracks failed on the first without).
TEST_F(DatasetGeneratorTest, ReindexRefusesAShardOfOtherSettingsAndClaimsOnlyTracksThatAreThere) {
  const fs::path dir = root_ / "merge-other";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  const fs::path file = dir / "flag-000002-v0" / "label.json";
  const std::string bytes = Bytes(file);
  // Fields by their JSON pointer; the error names them with dots. The nested ones, the wind and the
  // simulation beyond the header's count were merged without a word (a shard made with --warmup
  // 0.8 or --wind-max 3, or a larger run's folder).
  for (const auto& [pointer, value] : std::vector<std::pair<std::string, nlohmann::json>>{
           {"/dataset_seed", 2}, {"/width", 32}, {"/height", 32}, {"/num_frames", 5}, {"/split", "elsewhere"},
           {"/views", 2}, {"/frame_rate", 30}, {"/frame_pattern", "%03d.png"},
           {"/simulation_settings/warmup", 0.8}, {"/simulation_settings/max_edge", 0.5},
           {"/simulation_settings/scene", "other.json"}, {"/wind_speed", 12.5}}) {
    std::string field = pointer.substr(1);
    std::replace(field.begin(), field.end(), '/', '.');
    nlohmann::json label = nlohmann::json::parse(bytes);
    label[nlohmann::json::json_pointer(pointer)] = value;
    std::ofstream(file) << label.dump(2) << "\n";
    try {
      ReindexDataset(dir.string(), false);
      ADD_FAILURE() << field << " " << value << " was indexed";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string() + ": field '" + field + "' is " + value.dump()),
                std::string::npos)
          << e.what();
    }
  }
  std::ofstream(file, std::ios::binary) << bytes;
  // A larger run's folder (simulation 5 of a header counting 3: a run extending the dataset,
  // stopped before it rewrote the header) is listed and the count raised to cover it; refusing
  // it broke the reindex of a stopped run, which is what the reindex is for.
  {
    const fs::path larger = dir / "flag-000005-v0";
    fs::copy(dir / "flag-000002-v0", larger, fs::copy_options::recursive);
    nlohmann::json label = nlohmann::json::parse(bytes);
    label["name"] = "flag-000005-v0";
    label["simulation"] = 5;
    std::ofstream(larger / "label.json") << label.dump(2) << "\n";
    // A generating run of --count 3 leaves it out: it checks only its own simulations, and a
    // raised count would refuse its next run.
    EXPECT_EQ(GenerateDataset(Tiny(dir.string())).examples_in_index, 3);
    EXPECT_EQ(ReadIndex(dir.string())["count"], 3);
    EXPECT_EQ(ReindexDataset(dir.string(), false), 4);
    EXPECT_EQ(ReadIndex(dir.string())["count"], 6);
    fs::remove_all(larger);
  }
  // An example with a frame missing (a copy not finished) is left out, not listed for a reader to
  // fail on, and comes back once its frame does.
  const fs::path frame = dir / "flag-000001-v0" / "001.jpg";
  fs::rename(frame, root_ / "001.jpg");
  EXPECT_EQ(ReindexDataset(dir.string(), true), 2);
  // (The index held in a name: a range-for over ReadIndex(...)["clips"] read a freed temporary.)
  const nlohmann::json reindexed = ReadIndex(dir.string());
  for (const auto& clip : reindexed["clips"]) EXPECT_NE(clip["name"], "flag-000001-v0");
  fs::rename(root_ / "001.jpg", frame);
  // An example whose label.json is gone (frames without it) is left out and named.
  const fs::path label = dir / "flag-000001-v0" / "label.json";
  fs::rename(label, root_ / "label.json");
  testing::internal::CaptureStderr();
  EXPECT_EQ(ReindexDataset(dir.string(), false), 2);
  const std::string said = testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("1 folder without a label.json left out of the index: flag-000001-v0"), std::string::npos)
      << said;
  fs::rename(root_ / "label.json", label);
  nlohmann::json index = ReadIndex(dir.string());
  index["dataset"]["tracks"] = {4, 3};
  // A header's largest edge 0 is the scene's own: any edge a label records agrees with it.
  index["dataset"]["max_edge"] = 0.0;
  std::ofstream(dir / "index.json") << index.dump(2) << "\n";
  EXPECT_EQ(ReindexDataset(dir.string(), false), 3);
  EXPECT_FALSE(ReadIndex(dir.string())["dataset"].contains("tracks"));
}

// Two shards into one folder rebuilt its index at once: the index is rebuilt and written under an
// exclusive lock, and a run waits for another's to finish. A hidden folder whose number has more
// digits than an int64 (no name of ours) stopped the run with a bare "stoll".
TEST_F(DatasetGeneratorTest, TheIndexIsRebuiltUnderALock) {
  const fs::path dir = root_ / "locked";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  fs::create_directories(dir / ".flag-99999999999999999999-v0.tmp-x");
  const int fd = ::open((dir / ".index.lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);
  auto reindex = std::async(std::launch::async, [&] { return ReindexDataset(dir.string(), false); });
  auto generate = std::async(std::launch::async, [&] { return GenerateDataset(Tiny(dir.string())); });
  EXPECT_EQ(reindex.wait_for(std::chrono::milliseconds(500)), std::future_status::timeout);
  EXPECT_EQ(generate.wait_for(std::chrono::milliseconds(10)), std::future_status::timeout);
  ::close(fd);
  EXPECT_EQ(reindex.get(), 3);
  EXPECT_EQ(generate.get().examples_in_index, 3);
  EXPECT_TRUE(fs::exists(dir / ".flag-99999999999999999999-v0.tmp-x"));
}

// PGM frames are the grey of the colour frames, exactly: one channel, the weights of
// cv::IMREAD_GRAYSCALE, nothing lost (PNG as the lossless colour reference).
TEST_F(DatasetGeneratorTest, PgmFramesHoldTheGreyOfTheColourFrames) {
  DatasetOptions png = Tiny((root_ / "png").string());
  png.count = 1;
  png.frame_ext = "png";
  DatasetOptions pgm = png;
  pgm.out = (root_ / "pgm").string();
  pgm.frame_ext = "pgm";
  ASSERT_TRUE(GenerateDataset(png).errors.empty());
  ASSERT_TRUE(GenerateDataset(pgm).errors.empty());
  const std::string name = ExampleName(render::SceneKind::kFlag, 0, 0);
  const nlohmann::json label = ReadLabel((fs::path(pgm.out) / name / "label.json").string());
  EXPECT_EQ(label["encoding"], "mono8");
  EXPECT_EQ(label["frame_pattern"], "%03d.pgm");
  for (int f = 0; f < pgm.frames; ++f) {
    char file[16];
    std::snprintf(file, sizeof(file), "%03d", f);
    const cv::Mat colour = cv::imread((fs::path(png.out) / name / (std::string(file) + ".png")).string(),
                                      cv::IMREAD_UNCHANGED);
    const cv::Mat grey = cv::imread((fs::path(pgm.out) / name / (std::string(file) + ".pgm")).string(),
                                    cv::IMREAD_UNCHANGED);
    ASSERT_EQ(colour.channels(), 3) << file;
    ASSERT_EQ(grey.channels(), 1) << file;
    ASSERT_EQ(grey.type(), CV_8UC1) << file;
    cv::Mat expected;
    cv::cvtColor(colour, expected, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::norm(grey, expected, cv::NORM_INF), 0) << file;
    // Not a blank picture: the flag and the sky differ.
    double lo = 0, hi = 0;
    cv::minMaxLoc(grey, &lo, &hi);
    EXPECT_GT(hi - lo, 30) << file;
  }
}

TEST_F(DatasetGeneratorTest, AddTracksGivesADatasetTheTracksItWouldHaveBeenMadeWith) {
  ASSERT_TRUE(reference_.errors.empty());
  // Made with tracks: the same frames as the reference, and a tracks.json per example.
  DatasetOptions with = Tiny((root_ / "with-tracks").string());
  with.tracks = TrackGrid{4, 3};
  const DatasetSummary made = GenerateDataset(with);
  ASSERT_TRUE(made.errors.empty()) << made.errors[0];
  // The reference, made without, given its tracks afterwards.
  const fs::path added = root_ / "added-tracks";
  fs::copy(Ref(), added, fs::copy_options::recursive);
  DatasetOptions add = Tiny(added.string());
  add.tracks = TrackGrid{4, 3};
  add.add_tracks = true;
  const DatasetSummary s = GenerateDataset(add);
  ASSERT_TRUE(s.errors.empty()) << s.errors[0];
  EXPECT_EQ(s.examples_written, 3);
  for (int i = 0; i < 3; ++i) {
    const std::string name = ExampleName(render::SceneKind::kFlag, i, 0);
    const std::string tracks = Bytes(root_ / "with-tracks" / name / "tracks.json");
    const nlohmann::json j = nlohmann::json::parse(tracks);
    EXPECT_EQ(j["grid"], nlohmann::json({4, 3})) << name;
    EXPECT_EQ(j["xy"].size(), 6u) << name;
    EXPECT_EQ(Bytes(added / name / "tracks.json"), tracks) << name;
    for (int k = 0; k < 6; ++k) {
      char frame[16];
      std::snprintf(frame, sizeof(frame), "%03d.jpg", k);
      EXPECT_EQ(Bytes(root_ / "with-tracks" / name / frame), Bytes(Ref() / name / frame)) << name << frame;
      EXPECT_EQ(Bytes(added / name / frame), Bytes(Ref() / name / frame)) << name << frame;
    }
  }
  EXPECT_EQ(ReadIndex(added.string())["dataset"]["tracks"], nlohmann::json({4, 3}));
  // A folder an older generator made is given its tracks too (nothing is rendered into it), and
  // keeps its generator_version.
  const fs::path older = root_ / "older-tracks";
  fs::copy(Ref(), older, fs::copy_options::recursive);
  nlohmann::json older_index = ReadIndex(older.string());
  older_index["dataset"]["generator_version"] = kGeneratorVersion - 1;
  std::ofstream(older / "index.json") << older_index.dump(2) << "\n";
  for (const auto& clip : older_index["clips"]) {  // its labels say so too
    const fs::path file = older / clip["name"].get<std::string>() / "label.json";
    nlohmann::json label = ReadLabel(file.string());
    label["generator"]["version"] = kGeneratorVersion - 1;
    std::ofstream(file) << label.dump(2) << "\n";
  }
  DatasetOptions add_older = add;
  add_older.out = older.string();
  const DatasetSummary s_older = GenerateDataset(add_older);
  ASSERT_TRUE(s_older.errors.empty()) << s_older.errors[0];
  EXPECT_EQ(s_older.examples_written, 3);
  EXPECT_EQ(ReadIndex(older.string())["dataset"]["generator_version"], kGeneratorVersion - 1);
  EXPECT_EQ(ReadIndex(older.string())["dataset"]["tracks"], nlohmann::json({4, 3}));
  // --split: only that split's simulations are replayed.
  const fs::path some = root_ / "split-tracks";
  fs::copy(Ref(), some, fs::copy_options::recursive);
  DatasetOptions train_only = add;
  train_only.out = some.string();
  train_only.split = "train";
  const DatasetSummary t = GenerateDataset(train_only);
  ASSERT_TRUE(t.errors.empty()) << t.errors[0];
  int trained = 0;
  const nlohmann::json index = ReadIndex(some.string());
  for (const auto& clip : index["clips"]) {
    const bool is_train = clip["split"] == "train";
    trained += is_train;
    EXPECT_EQ(fs::exists(some / clip["name"].get<std::string>() / "tracks.json"), is_train) << clip["name"];
  }
  EXPECT_EQ(t.examples_written, trained);
  EXPECT_GT(trained, 0);
  // The other splits still lack theirs: the header does not claim the grid until they have them.
  EXPECT_EQ(t.examples_without_tracks, static_cast<int64_t>(index["clips"].size()) - trained);
  EXPECT_FALSE(index["dataset"].contains("tracks"));
  DatasetOptions rest = add;
  rest.out = some.string();
  const DatasetSummary completed = GenerateDataset(rest);
  ASSERT_TRUE(completed.errors.empty()) << completed.errors[0];
  EXPECT_EQ(completed.examples_without_tracks, 0);
  EXPECT_EQ(ReadIndex(some.string())["dataset"]["tracks"], nlohmann::json({4, 3}));
  EXPECT_EQ(ReadIndex((root_ / "with-tracks").string())["dataset"]["tracks"], nlohmann::json({4, 3}));
  // Again: nothing left to do.
  EXPECT_EQ(GenerateDataset(add).simulated, 0);
  // Tracks written before the points' positions were stored are made again, with them; the others stay.
  const std::string name0 = ExampleName(render::SceneKind::kFlag, 0, 0);
  nlohmann::json old = nlohmann::json::parse(Bytes(added / name0 / "tracks.json"));
  ASSERT_TRUE(old.contains("world"));
  old.erase("world");
  std::ofstream(added / name0 / "tracks.json") << old.dump() << "\n";
  const DatasetSummary upgraded = GenerateDataset(add);
  ASSERT_TRUE(upgraded.errors.empty()) << upgraded.errors[0];
  EXPECT_EQ(upgraded.examples_written, 1);
  EXPECT_EQ(Bytes(added / name0 / "tracks.json"), Bytes(root_ / "with-tracks" / name0 / "tracks.json"));
  // The check reads the file's head only (up to "world"): a copy cut short after it is still
  // made again, and so is one of another grid, or one whose keys come in another order but hold
  // everything (kept).
  const std::string whole = Bytes(added / name0 / "tracks.json");
  std::ofstream(added / name0 / "tracks.json") << whole.substr(0, whole.find("\"world\"") + 40);
  EXPECT_EQ(GenerateDataset(add).examples_written, 1);
  EXPECT_EQ(Bytes(added / name0 / "tracks.json"), whole);
  nlohmann::json other = nlohmann::json::parse(whole);
  other["grid"] = {5, 3};
  std::ofstream(added / name0 / "tracks.json") << other.dump() << "\n";
  EXPECT_EQ(GenerateDataset(add).examples_written, 1);
  EXPECT_EQ(Bytes(added / name0 / "tracks.json"), whole);
  {
    std::string reordered = "{\"world\":" + nlohmann::json::parse(whole)["world"].dump();
    nlohmann::json rest = nlohmann::json::parse(whole);
    rest.erase("world");
    for (auto it = rest.begin(); it != rest.end(); ++it) reordered += ",\"" + it.key() + "\":" + it.value().dump();
    std::ofstream(added / name0 / "tracks.json") << reordered << "}\n";
    EXPECT_EQ(GenerateDataset(add).examples_written, 0);
    std::ofstream(added / name0 / "tracks.json") << whole;
  }
  // Resuming a dataset made without tracks with --tracks alone would leave its examples without:
  // refused, pointing at --add-tracks.
  const fs::path plain = root_ / "plain-resumed-with-tracks";
  fs::copy(Ref(), plain, fs::copy_options::recursive);
  DatasetOptions resume = Tiny(plain.string());
  resume.tracks = TrackGrid{4, 3};
  try {
    GenerateDataset(resume);
    ADD_FAILURE() << "a dataset without tracks was resumed with --tracks";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'dataset.tracks'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--add-tracks"), std::string::npos) << e.what();
  }
  // The other way: a dataset made with tracks resumed without them would make examples without
  // tracks.json and drop "tracks" from its header. Refused, saying which grid to resume with.
  const fs::path tracked = root_ / "tracked-resumed-without";
  fs::copy(root_ / "with-tracks", tracked, fs::copy_options::recursive);
  const std::string header_before = Bytes(tracked / "index.json");
  DatasetOptions without = Tiny(tracked.string());
  without.count += 1;
  try {
    GenerateDataset(without);
    ADD_FAILURE() << "a dataset with tracks was resumed without them";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'dataset.tracks' is [4,3] but this run has none (resume with --tracks 4x3)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(Bytes(tracked / "index.json"), header_before);
  // --add-tracks with another grid than the header's: refused (the header named the new grid
  // over files of the old one).
  DatasetOptions other_grid = Tiny(tracked.string());
  other_grid.tracks = TrackGrid{5, 4};
  other_grid.add_tracks = true;
  EXPECT_NE(GenerateError(other_grid).find("field 'dataset.tracks' is [4,3] but this run adds [5,4]"),
            std::string::npos)
      << GenerateError(other_grid);
  // A header without a grid (some examples still without tracks) and files of another grid:
  // they are made again with this run's, so the dataset holds one grid.
  nlohmann::json gridless = nlohmann::json::parse(Bytes(tracked / "index.json"));
  gridless["dataset"].erase("tracks");
  std::ofstream(tracked / "index.json") << gridless.dump(2) << "\n";
  other_grid.tracks = TrackGrid{3, 4};
  const DatasetSummary regridded = GenerateDataset(other_grid);
  ASSERT_TRUE(regridded.errors.empty()) << regridded.errors[0];
  EXPECT_EQ(regridded.examples_written, 3);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(nlohmann::json::parse(Bytes(tracked / ExampleName(render::SceneKind::kFlag, i, 0) / "tracks.json"))["grid"],
              nlohmann::json({3, 4}));
  EXPECT_EQ(nlohmann::json::parse(Bytes(tracked / "index.json"))["dataset"]["tracks"], nlohmann::json({3, 4}));
}

TEST_F(DatasetGeneratorTest, AddTracksRefusesAnExampleWhoseFramesItsReplayDoesNotShow) {
  ASSERT_TRUE(reference_.errors.empty());
  const fs::path dir = root_ / "tampered";
  fs::copy(Ref(), dir, fs::copy_options::recursive);
  // Example 1's last frame mirrored: the cloth is not where its simulation puts it.
  const fs::path last = dir / ExampleName(render::SceneKind::kFlag, 1, 0) / "005.jpg";
  cv::Mat image = cv::imread(last.string());
  cv::flip(image, image, 1);
  ASSERT_TRUE(cv::imwrite(last.string(), image));
  DatasetOptions add = Tiny(dir.string());
  add.tracks = TrackGrid{4, 3};
  add.add_tracks = true;
  const DatasetSummary s = GenerateDataset(add);
  ASSERT_EQ(s.failed, 1);
  EXPECT_NE(s.errors[0].find(last.string()), std::string::npos) << s.errors[0];
  EXPECT_NE(s.errors[0].find("grey levels"), std::string::npos) << s.errors[0];
  EXPECT_FALSE(fs::exists(last.parent_path() / "tracks.json"));
  // One example without its tracks: the header records no grid, so training or a resume with
  // --tracks are not told every example has them.
  EXPECT_EQ(s.examples_without_tracks, 1);
  EXPECT_FALSE(ReadIndex(dir.string())["dataset"].contains("tracks"));
  EXPECT_TRUE(fs::exists(dir / ExampleName(render::SceneKind::kFlag, 0, 0) / "tracks.json"));
  EXPECT_TRUE(fs::exists(dir / ExampleName(render::SceneKind::kFlag, 2, 0) / "tracks.json"));
  // Other settings than the dataset's are refused before anything runs.
  add.seed = 2;
  EXPECT_THROW(GenerateDataset(add), std::runtime_error);
}

TEST(DatasetOptionsTest, AddTracksNeedsAGridAndADataset) {
  DatasetOptions o;
  o.out = (fs::temp_directory_path() / ("clothwind_no_dataset_" + std::to_string(::getpid()))).string();
  o.count = 1;
  o.add_tracks = true;
  EXPECT_THROW(GenerateDataset(o), std::invalid_argument);
  o.tracks = TrackGrid{};
  try {
    GenerateDataset(o);
    ADD_FAILURE() << "an empty folder has no dataset";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("--add-tracks"), std::string::npos) << e.what();
  }
  fs::remove_all(o.out);
}

// A label whose frame_pattern printf would misread ("%s" reads a string from nowhere: the contact
// sheet and the index crashed) is refused naming the file and the field.
TEST_F(DatasetGeneratorTest, BadFramePatternIsRefusedByName) {
  const fs::path dir = root_ / "bad_pattern";
  fs::create_directories(dir);
  fs::copy(Ref() / "flag-000000-v0", dir / "flag-000000-v0", fs::copy_options::recursive);
  fs::copy(Ref() / "index.json", dir / "index.json");
  const fs::path label = dir / "flag-000000-v0" / "label.json";
  nlohmann::json j;
  {
    std::ifstream in(label);
    j = nlohmann::json::parse(in);
  }
  j["frame_pattern"] = "%s.jpg";
  std::ofstream(label) << j.dump();
  try {
    ReindexDataset(dir.string());
    ADD_FAILURE() << "a frame_pattern of %s was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("frame_pattern"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(label.string()), std::string::npos) << e.what();
  }
}

// The contact sheet tiles the dataset's own folders: a name leading out of it is refused naming
// the entry, and a clip without a wind speed is still shown (sorted last).
TEST_F(DatasetGeneratorTest, ContactSheetStaysInsideTheDataset) {
  nlohmann::json index = ReadIndex(Ref().string());
  ContactSheetOptions o;
  o.tile = 32;
  std::vector<std::pair<int, int>> reports;
  const cv::Mat sheet =
      MakeContactSheet(Ref().string(), index, o, [&](int done, int total) { reports.emplace_back(done, total); });
  EXPECT_FALSE(sheet.empty());
  EXPECT_EQ(reports, (std::vector<std::pair<int, int>>{{0, 3}, {1, 3}, {2, 3}, {3, 3}}));
  // A clip without a wind (a recording's unlabelled one) is shown, last: the third of the 2x2
  // sheet's tiles is the one a sheet of that clip alone shows.
  index["clips"][0].erase("wind_speed");
  const cv::Mat with_unlabelled = MakeContactSheet(Ref().string(), index, o);
  ASSERT_EQ(with_unlabelled.size(), cv::Size(64, 64));
  nlohmann::json alone = index;
  alone["clips"] = nlohmann::json::array({index["clips"][0]});
  const cv::Mat single = MakeContactSheet(Ref().string(), alone, o);
  ASSERT_EQ(single.size(), cv::Size(32, 32));
  EXPECT_EQ(cv::norm(with_unlabelled(cv::Rect(0, 32, 32, 32)), single, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(with_unlabelled(cv::Rect(0, 0, 32, 32)), single, cv::NORM_INF), 0.0);
  for (const char* bad : {"../reference", "/tmp"}) {
    index["clips"][1]["name"] = bad;
    try {
      MakeContactSheet(Ref().string(), index, o);
      ADD_FAILURE() << bad << " was read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("clips[1].name must be a folder name"), std::string::npos) << e.what();
    }
  }
}

TEST(DatasetOptionsTest, BadOptionsAreRejected) {
  DatasetOptions o;
  o.out = "/tmp/never";
  o.count = 1;
  o.shards = 2;
  o.shard = 2;
  EXPECT_THROW(GenerateDataset(o), std::invalid_argument);
  o.shard = 0;
  o.views = 0;
  EXPECT_THROW(GenerateDataset(o), std::invalid_argument);
  o.views = 1;
  o.frame_ext = "ppm";
  EXPECT_THROW(GenerateDataset(o), std::invalid_argument);
  o.frame_ext = "jpg";
  const double warmup = o.warmup;
  o.warmup = 0.019;  // between frames 0 and 1 at 25 fps: was rounded to 0 without a word
  EXPECT_THROW(GenerateDataset(o), std::invalid_argument);
  o.warmup = warmup;
  o.frame_ext = "jpg";
  o.count = 100000000000;  // hung without a word, building a to-do list of 1e11 entries
  try {
    GenerateDataset(o);
    ADD_FAILURE() << "--count 1e11 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--count must be in 0..1000000"), std::string::npos) << e.what();
  }
  o.count = 1;
  // Split fractions that cannot be: refused before the folder's header records them.
  o.val_fraction = 0.9;
  o.test_fraction = 0.5;
  try {
    GenerateDataset(o);
    ADD_FAILURE() << "--val 0.9 --test 0.5 was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--val and --test"), std::string::npos) << e.what();
  }
  o.val_fraction = 0.1;
  o.test_fraction = 0.1;
  // Infinite values passed ">= 0" checks, ran as something else (lround(inf) = 0 s of warm-up)
  // and went into the header as null, which every corrected run was refused against.
  for (const char* which : {"warmup", "fps", "max_edge"}) {
    DatasetOptions bad = o;
    const double inf = std::numeric_limits<double>::infinity();
    (std::string(which) == "warmup" ? bad.warmup : std::string(which) == "fps" ? bad.fps : bad.max_edge) = inf;
    EXPECT_THROW(GenerateDataset(bad), std::invalid_argument) << which;
  }
  EXPECT_FALSE(fs::exists(o.out));
}

}  // namespace
}  // namespace clothwind::data
