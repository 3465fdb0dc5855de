// The dataset reader on a generated dataset in the docs/dataset.md format, its errors on bad
// input, and the augmentations (shapes, determinism by seed, what each one does).
#include "learn/dataset.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/scoped_file_size_limit.h"

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

class DatasetTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("clothwind_learn_dataset_" + std::to_string(::getpid())));
    ToyDatasetOptions o;
    o.clips = 10;
    o.frames = 40;
    o.size = 48;
    frequencies_ = new std::vector<double>(WriteToyDataset(*dir_, o));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete frequencies_;
  }
  // A copy of the dataset to break.
  fs::path Copy(const std::string& name) {
    const fs::path copy = fs::temp_directory_path() / ("clothwind_learn_bad_" + name + std::to_string(::getpid()));
    fs::remove_all(copy);
    fs::copy(*dir_, copy, fs::copy_options::recursive);
    copies_.push_back(copy);
    return copy;
  }
  void TearDown() override {
    for (const auto& c : copies_) fs::remove_all(c);
  }
  static fs::path* dir_;
  static std::vector<double>* frequencies_;
  std::vector<fs::path> copies_;
};
fs::path* DatasetTest::dir_ = nullptr;
std::vector<double>* DatasetTest::frequencies_ = nullptr;

void EditJson(const fs::path& file, const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = nlohmann::json::parse(std::ifstream(file));
  edit(j);
  std::ofstream(file) << j.dump();
}

// An index entry's field error says which of its (thousands of) entries: "missing field
// \"name\"" alone left the user to search the file.
TEST_F(DatasetTest, AnIndexEntrysFieldErrorNamesTheEntry) {
  const fs::path bad = Copy("entry_field");
  EditJson(bad / "index.json", [](nlohmann::json& j) { j["clips"][5].erase("name"); });
  try {
    ReadDataset(bad);
    FAIL() << "an entry without a name was read";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("index.json: missing field \"clips[5].name\""));
  }
  const fs::path wrong = Copy("entry_type");
  EditJson(wrong / "index.json", [](nlohmann::json& j) { j["clips"][3]["wind_speed"] = "3.1"; });
  try {
    ReadDataset(wrong);
    FAIL() << "a wind speed given as text was read";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("field \"clips[3].wind_speed\" must be a number [m/s], got \"3.1\""));
  }
}

TEST_F(DatasetTest, ReadsIndexLabelsAndFrames) {
  const Dataset d = ReadDataset(*dir_);
  ASSERT_EQ(d.clips.size(), 10u);
  EXPECT_EQ(d.kind, "toy");
  int per_split[3] = {0, 0, 0};
  for (const ClipInfo& c : d.clips) {
    EXPECT_EQ(c.num_frames, 40);
    EXPECT_EQ(c.width, 48);
    EXPECT_DOUBLE_EQ(c.frame_rate, 25);
    EXPECT_GE(c.wind_speed, 0);
    EXPECT_LE(c.wind_speed, 10);
    EXPECT_EQ(c.simulation, -1);  // the toy index names no simulations
    per_split[c.split == "train" ? 0 : c.split == "val" ? 1 : 2]++;
  }
  EXPECT_EQ(SelectSplit(d, "all").size(), 10u);
  EXPECT_EQ(static_cast<int>(SelectSplit(d, "train").size()), per_split[0]);
  EXPECT_EQ(static_cast<int>(SelectSplit(d, "val").size()), per_split[1]);
  EXPECT_THROW(SelectSplit(d, "training"), std::invalid_argument);
  // The label is the generator's: the stripes' frequency is a known function of wind speed.
  for (size_t i = 0; i < d.clips.size(); ++i) {
    EXPECT_NEAR((*frequencies_)[i], 1.0 + 0.5 * d.clips[i].wind_speed, 1e-9);
  }
  const std::vector<cv::Mat> frames = LoadFrames(d.clips[0], 5, 3);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[0].type(), CV_8UC1);
  EXPECT_EQ(frames[0].size(), cv::Size(48, 48));
  EXPECT_THROW(LoadFrames(d.clips[0], 38, 3), std::runtime_error);
  // In colour, YCrCb: the toy's frames are grey, so Y is the grey frame and Cr, Cb sit at 128.
  const std::vector<cv::Mat> colour = LoadFrames(d.clips[0], 5, 3, true);
  ASSERT_EQ(colour.size(), 3u);
  ASSERT_EQ(colour[0].type(), CV_8UC3);
  std::vector<cv::Mat> ycc;
  cv::split(colour[1], ycc);
  EXPECT_LE(cv::norm(ycc[0], frames[1], cv::NORM_INF), 1.0);
  EXPECT_LE(cv::norm(ycc[1], cv::Mat(48, 48, CV_8U, cv::Scalar(128)), cv::NORM_INF), 1.0);
  EXPECT_LE(cv::norm(ycc[2], cv::Mat(48, 48, CV_8U, cv::Scalar(128)), cv::NORM_INF), 1.0);
  EXPECT_THROW(LoadFrames(d.clips[0], 38, 3, true), std::runtime_error);
}

// A "dataset" header whose "variant" is of another type is no variant: value() with a string
// default threw a bare type error naming no file, from every verb that reads a dataset.
TEST_F(DatasetTest, AVariantOfAnotherTypeIsNoVariant) {
  const fs::path d = Copy("variant_number");
  EditJson(d / "index.json", [](nlohmann::json& j) { j["dataset"] = {{"variant", 1}}; });
  EXPECT_EQ(ReadDataset(d).clips.size(), ReadDataset(*dir_).clips.size());
}

TEST_F(DatasetTest, BadInputErrorsNameTheFileAndField) {
  auto expect_error = [](const fs::path& dir, const std::string& file, const std::string& what) {
    try {
      const Dataset d = ReadDataset(dir);
      for (const ClipInfo& c : d.clips) LoadFrames(c, 0, c.num_frames);
      ADD_FAILURE() << "no error for " << what;
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr(file)) << what;
      EXPECT_THAT(e.what(), HasSubstr(what));
    }
  };
  {
    const fs::path d = Copy("noindex");
    fs::remove(d / "index.json");
    expect_error(d, (d / "index.json").string(), "cannot open");
  }
  {
    const fs::path d = Copy("format");
    EditJson(d / "index.json", [](nlohmann::json& j) { j["format"] = "something"; });
    expect_error(d, (d / "index.json").string(), "\"format\"");
  }
  {
    const fs::path d = Copy("kind");
    EditJson(d / "index.json", [](nlohmann::json& j) { j["kind"] = "flags"; });
    expect_error(d, (d / "index.json").string(), "\"kind\" is \"flags\"");
  }
  {
    const fs::path d = Copy("speed");
    EditJson(d / "toy-00003" / "label.json", [](nlohmann::json& j) { j.erase("wind_speed"); });
    expect_error(d, (d / "toy-00003" / "label.json").string(), "\"wind_speed\"");
  }
  {
    const fs::path d = Copy("type");
    EditJson(d / "toy-00002" / "label.json", [](nlohmann::json& j) { j["num_frames"] = "many"; });
    expect_error(d, (d / "toy-00002" / "label.json").string(), "\"num_frames\"");
  }
  {
    const fs::path d = Copy("pattern");
    EditJson(d / "toy-00001" / "label.json", [](nlohmann::json& j) { j["frame_pattern"] = "%s.jpg"; });
    expect_error(d, (d / "toy-00001" / "label.json").string(), "\"frame_pattern\"");
  }
  {
    const fs::path d = Copy("frame");
    fs::remove(d / "toy-00004" / "017.jpg");
    expect_error(d, (d / "toy-00004" / "017.jpg").string(), "missing");
  }
  {
    const fs::path d = Copy("size");
    cv::imwrite((d / "toy-00005" / "000.jpg").string(), cv::Mat(30, 48, CV_8UC1, cv::Scalar(7)));
    expect_error(d, (d / "toy-00005" / "000.jpg").string(), "48x30");
  }
  {
    const fs::path d = Copy("simulation");
    EditJson(d / "index.json", [](nlohmann::json& j) { j["clips"][6]["simulation"] = -2; });
    expect_error(d, (d / "index.json").string(), "clips[6].simulation must be >= 0, got -2");
  }
  {
    const fs::path d = Copy("json");
    std::ofstream(d / "toy-00000" / "label.json") << "{ not json";
    expect_error(d, (d / "toy-00000" / "label.json").string(), "not valid JSON");
  }
  {
    // Another clip's label copied in: its wind was read for this clip without a word.
    const fs::path d = Copy("other_label");
    fs::copy_file(d / "toy-00001" / "label.json", d / "toy-00000" / "label.json",
                  fs::copy_options::overwrite_existing);
    expect_error(d, (d / "toy-00000" / "label.json").string(),
                 "field \"name\" is \"toy-00001\", expected the clip's \"toy-00000\"");
  }
  // Integers that get<int> would truncate or wrap, winds no anemometer reads, a clip listed
  // twice, a split of the wrong type, a folder where the label should be, and an image whose
  // header claims more pixels than OpenCV allows (imread throws: it ended the replay camera).
  {
    const fs::path d = Copy("fraction");
    EditJson(d / "toy-00002" / "label.json", [](nlohmann::json& j) { j["num_frames"] = 30.7; });
    expect_error(d, (d / "toy-00002" / "label.json").string(), "\"num_frames\" must be");
  }
  {
    const fs::path d = Copy("wrap");
    EditJson(d / "toy-00002" / "label.json", [](nlohmann::json& j) { j["width"] = 4294967328LL; });
    expect_error(d, (d / "toy-00002" / "label.json").string(), "4294967328");
  }
  {
    const fs::path d = Copy("huge");
    EditJson(d / "toy-00002" / "label.json", [](nlohmann::json& j) { j["num_frames"] = 2000000000; });
    expect_error(d, (d / "toy-00002" / "label.json").string(), "\"num_frames\" must be in 1..100000");
  }
  for (const double speed : {-50.0, 1e300}) {
    const fs::path d = Copy("wind" + std::to_string(speed > 0));
    EditJson(d / "toy-00003" / "label.json", [speed](nlohmann::json& j) { j["wind_speed"] = speed; });
    expect_error(d, (d / "toy-00003" / "label.json").string(), "\"wind_speed\" must be a speed in 0..100 m/s");
    // Said as written (std::to_string wrote 1e300 as 301 digits, -50 as -50.000000).
    try {
      ReadDataset(d);
      ADD_FAILURE() << "wind " << speed << " accepted";
    } catch (const std::runtime_error& e) {
      const std::string what = e.what(), said = speed > 0 ? "got 1e+300" : "got -50";
      EXPECT_EQ(what.substr(what.size() - std::min(what.size(), said.size())), said) << what;
    }
  }
  {
    const fs::path d = Copy("twice");
    EditJson(d / "index.json", [](nlohmann::json& j) {
      nlohmann::json again = j["clips"][0];
      again["split"] = "test";
      j["clips"].push_back(again);
    });
    expect_error(d, (d / "index.json").string(), "repeats clips[0]");
  }
  {
    const fs::path d = Copy("split_type");
    EditJson(d / "index.json", [](nlohmann::json& j) { j["clips"][1]["split"] = 5; });
    expect_error(d, (d / "index.json").string(), "\"clips[1].split\" must be");
  }
  {
    const fs::path d = Copy("label_folder");
    fs::remove(d / "toy-00001" / "label.json");
    fs::create_directories(d / "toy-00001" / "label.json");
    expect_error(d, (d / "toy-00001" / "label.json").string(), "a folder");
  }
  {
    // A clip at another rate than the model reads: refused by name (its frequencies would read as
    // another wind).
    const fs::path d = Copy("rate");
    EditJson(d / "toy-00002" / "label.json", [](nlohmann::json& j) { j["frame_rate"] = 5.0; });
    const Dataset data = ReadDataset(d);
    try {
      CheckClipsSuitModel(data.clips, 25.0, false, 1);
      ADD_FAILURE() << "a 5 Hz clip was accepted for a 25 Hz model";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr((d / "toy-00002" / "label.json").string()));
      EXPECT_THAT(e.what(), HasSubstr("the model reads clips at 25"));
    }
    EXPECT_NO_THROW(CheckClipsSuitModel(ReadDataset(Copy("rate_ok")).clips, 25.1, false, 1));  // within 1 %
  }
  {
    // A clip shorter than the model's window: refused up front by name (it failed when its turn
    // came, after a training epoch, naming no clip).
    const fs::path d = Copy("short");
    const Dataset data = ReadDataset(d);
    const int frames = data.clips[3].num_frames;
    EditJson(d / "toy-00003" / "label.json", [&](nlohmann::json& j) { j["num_frames"] = frames - 1; });
    try {
      CheckClipsSuitModel(ReadDataset(d).clips, 25.0, false, frames);
      ADD_FAILURE() << "a clip of " << frames - 1 << " frames was accepted for a " << frames << "-frame model";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr((d / "toy-00003" / "label.json").string() + ": field \"num_frames\""));
    }
    EXPECT_NO_THROW(CheckClipsSuitModel(data.clips, 25.0, false, frames));
  }
  {
    // Two winds under one simulation index (a merge gone wrong): refused when read, naming both
    // clips, not after eval has predicted every clip.
    const fs::path d = Copy("simulation_winds");
    EditJson(d / "index.json", [](nlohmann::json& j) {
      j["clips"][0]["simulation"] = 7;
      j["clips"][4]["simulation"] = 7;
    });
    expect_error(d, (d / "index.json").string() + ": simulation 7 has clips of two winds", "toy-00004");
  }
  {
    // Grey clips for a colour model: refused by name (two of its three channels would be constant).
    const fs::path d = Copy("grey_for_colour");
    try {
      CheckClipsSuitModel(ReadDataset(d).clips, 25.0, true, 1);
      ADD_FAILURE() << "mono8 clips were accepted for a colour model";
    } catch (const std::runtime_error& e) {
      EXPECT_THAT(e.what(), HasSubstr("label.json: field \"encoding\" is \"mono8\""));
    }
    EditJson(d / "index.json", [](nlohmann::json& j) {
      for (auto& c : j["clips"]) c.erase("wind_speed");  // and nothing else differs
    });
    for (const ClipInfo& c : ReadDataset(d).clips)
      EditJson(c.dir / "label.json", [](nlohmann::json& j) { j["encoding"] = "rgb8"; });
    EXPECT_NO_THROW(CheckClipsSuitModel(ReadDataset(d).clips, 25.0, true, 1));
  }
  {
    // The index and a label disagreeing on a clip's wind: refused naming both files.
    const fs::path d = Copy("two_winds");
    EditJson(d / "toy-00002" / "label.json", [](nlohmann::json& j) { j["wind_speed"] = j["wind_speed"].get<double>() + 0.5; });
    expect_error(d, (d / "index.json").string() + ": clips[2].wind_speed", "toy-00002/label.json says");
  }
  {
    const fs::path d = Copy("bomb");
    std::ofstream(d / "toy-00004" / "014.jpg", std::ios::binary) << "P5\n100000 100000\n255\n";
    expect_error(d, (d / "toy-00004" / "014.jpg").string(), "not a readable image");
  }
  {
    // A frame cut short (a copy interrupted): cv::imread decodes it with grey rows and only warns;
    // the reader refuses it by name.
    const fs::path d = Copy("cut");
    const fs::path frame = d / "toy-00001" / "007.jpg";
    fs::resize_file(frame, fs::file_size(frame) / 2);
    ASSERT_FALSE(cv::imread(frame.string()).empty());
    expect_error(d, frame.string(), "JPEG truncated");
  }
}

// Gives clip i the wind of clip i - 1 (index and label) for each odd i in `odd` (all odd clips
// when empty): the views of one simulation film one wind.
void ShareWindsInPairs(const fs::path& d, const std::vector<size_t>& odd) {
  nlohmann::json index;
  std::ifstream(d / "index.json") >> index;
  for (size_t i = 1; i < index["clips"].size(); i += 2) {
    if (!odd.empty() && std::find(odd.begin(), odd.end(), i) == odd.end()) continue;
    const std::string first = index["clips"][i - 1]["name"], second = index["clips"][i]["name"];
    nlohmann::json label;
    std::ifstream(d / first / "label.json") >> label;
    const double wind = label["wind_speed"];
    EditJson(d / second / "label.json", [&](nlohmann::json& j) { j["wind_speed"] = wind; });
    EditJson(d / "index.json", [&](nlohmann::json& j) {
      if (j["clips"][i].contains("wind_speed")) j["clips"][i]["wind_speed"] = wind;
    });
  }
}

// A recorded dataset (kind "real") in which one clip got no wind label (the anemometer started
// late): that clip is left out and counted, the others read; one such clip made train and eval
// refuse the whole field dataset. In any other kind a null wind stays an error.
TEST_F(DatasetTest, ARecordedClipWithoutAWindLabelIsLeftOutAndCounted) {
  const fs::path real = Copy("real");
  EditJson(real / "index.json", [](nlohmann::json& j) {
    j["kind"] = "real";
    j["clips"][3]["wind_speed"] = nullptr;
  });
  const nlohmann::json index = nlohmann::json::parse(std::ifstream(real / "index.json"));
  const std::string name = index["clips"][3]["name"];
  EditJson(real / name / "label.json", [](nlohmann::json& j) { j["wind_speed"] = nullptr; });
  const Dataset d = ReadDataset(real);
  EXPECT_EQ(d.unlabelled, 1u);
  EXPECT_EQ(d.clips.size(), index["clips"].size() - 1);
  for (const ClipInfo& c : d.clips) EXPECT_NE(c.name, name);
  // Counted in its own split, and in that one only (eval --split test said the train split's
  // unlabelled clips were left out of the test split).
  const std::string split = index["clips"][3]["split"];
  for (const char* other : {"train", "val", "test"}) {
    EXPECT_EQ(UnlabelledIn(d, other), other == split ? 1u : 0u) << other;
  }
  EXPECT_EQ(UnlabelledIn(d, "all"), 1u);
  // An unlabelled clip's split is checked as any other's.
  EditJson(real / "index.json", [](nlohmann::json& j) { j["clips"][3]["split"] = "holdout"; });
  try {
    ReadDataset(real);
    ADD_FAILURE() << "an unlabelled clip of split \"holdout\" was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("clips[3].split must be"), std::string::npos) << e.what();
  }
  const fs::path toy = Copy("toy-null");
  EditJson(toy / name / "label.json", [](nlohmann::json& j) { j["wind_speed"] = nullptr; });
  try {
    ReadDataset(toy);
    FAIL() << "a toy clip without its wind was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("wind_speed"), std::string::npos) << e.what();
  }
}

TEST_F(DatasetTest, ReadsEachClipsSimulation) {
  // A simulated dataset's index names each clip's simulation; its views share it.
  // Pairs of clips, each pair in its first clip's split (index and label agreeing).
  const fs::path d = Copy("simulations");
  std::vector<std::string> names;
  EditJson(d / "index.json", [&](nlohmann::json& j) {
    for (size_t i = 0; i < j["clips"].size(); ++i) {
      j["clips"][i]["simulation"] = static_cast<int>(i / 2);
      if (i % 2 == 1) j["clips"][i]["split"] = j["clips"][i - 1]["split"];
      names.push_back(j["clips"][i]["name"].get<std::string>() + "=" + j["clips"][i]["split"].get<std::string>());
    }
  });
  for (const std::string& n : names) {
    const std::string name = n.substr(0, n.find('=')), split = n.substr(n.find('=') + 1);
    EditJson(d / name / "label.json", [&](nlohmann::json& j) { j["split"] = split; });
  }
  ShareWindsInPairs(d, {});
  const Dataset dataset = ReadDataset(d);
  ASSERT_EQ(dataset.clips.size(), 10u);
  for (size_t i = 0; i < dataset.clips.size(); ++i) EXPECT_EQ(dataset.clips[i].simulation, static_cast<int>(i / 2));

  // One simulation in two splits (a merged or re-indexed dataset): its test views' motion would be
  // trained on. Refused, naming the simulation and both clips.
  const fs::path leak = Copy("leak");
  std::string first_split;
  EditJson(leak / "index.json", [&](nlohmann::json& j) {
    for (auto& c : j["clips"]) c.erase("split");  // the labels' splits, then
    j["clips"][0]["simulation"] = 7;
    j["clips"][1]["simulation"] = 7;
  });
  ShareWindsInPairs(leak, {1});
  EditJson(leak / "toy-00000" / "label.json", [](nlohmann::json& j) { j["split"] = "train"; });
  EditJson(leak / "toy-00001" / "label.json", [](nlohmann::json& j) { j["split"] = "test"; });
  try {
    ReadDataset(leak);
    ADD_FAILURE() << "a simulation in two splits was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("simulation 7 has clips in two splits (\"toy-00000\" in train, \"toy-00001\" in test)"));
  }
  // Unless the index says it was split clip by clip on purpose (scripts/dataset-variant
  // --split-by-clip, which measures that leak): then its splits hold.
  EditJson(leak / "index.json", [&](nlohmann::json& j) {
    j["dataset"] = {{"variant", "split_by_clip"}};
    j["clips"][0]["split"] = "test";
    j["clips"][1]["split"] = "train";
  });
  const Dataset variant = ReadDataset(leak);
  EXPECT_EQ(variant.clips[0].split, "test");
  EXPECT_EQ(variant.clips[1].split, "train");
  // The index and a label naming different splits for one clip: which holds is a guess.
  const fs::path two = Copy("two_splits");
  std::string listed;
  EditJson(two / "index.json", [&](nlohmann::json& j) { listed = j["clips"][3]["split"].get<std::string>(); });
  EditJson(two / "toy-00003" / "label.json",
           [&](nlohmann::json& j) { j["split"] = listed == "test" ? "train" : "test"; });
  try {
    ReadDataset(two);
    ADD_FAILURE() << "an index and a label with two splits for a clip were accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("clips[3].split is"));
    EXPECT_THAT(e.what(), HasSubstr("toy-00003/label.json says"));
  }
}

double Mean(const std::vector<float>& v) { return std::accumulate(v.begin(), v.end(), 0.0) / v.size(); }

TEST_F(DatasetTest, AugmentationShapesAndDeterminismBySeed) {
  const ClipInfo clip = ReadDataset(*dir_).clips[0];
  SampleOptions o;
  o.frames = 30;
  o.input_size = 32;
  o.augment = true;
  const Sample a = LoadSample(clip, o, 7), b = LoadSample(clip, o, 7);
  ASSERT_EQ(a.pixels.size(), 30u * 32 * 32);
  EXPECT_EQ(a.pixels, b.pixels);
  EXPECT_EQ(a.first_frame, b.first_frame);
  EXPECT_EQ(a.crop, b.crop);
  EXPECT_FLOAT_EQ(a.wind_speed, static_cast<float>(clip.wind_speed));
  // Per-clip normalisation: zero mean, unit standard deviation over the whole clip.
  double m = Mean(a.pixels), var = 0;
  for (float p : a.pixels) var += (p - m) * (p - m);
  EXPECT_NEAR(m, 0, 1e-4);
  EXPECT_NEAR(std::sqrt(var / a.pixels.size()), 1, 1e-3);
  // Over seeds, every augmentation varies: offset in [0, 10], crop scales, flips.
  std::set<int> offsets, crops;
  int flipped = 0;
  bool differs = false;
  for (uint64_t seed = 0; seed < 40; ++seed) {
    const Sample s = LoadSample(clip, o, seed);
    ASSERT_EQ(s.pixels.size(), a.pixels.size());
    EXPECT_GE(s.first_frame, 0);
    EXPECT_LE(s.first_frame, 10);
    EXPECT_TRUE(s.crop.x >= 0 && s.crop.y >= 0 && s.crop.br().x <= 48 && s.crop.br().y <= 48);
    EXPECT_EQ(s.crop.width, s.crop.height);
    offsets.insert(s.first_frame);
    crops.insert(s.crop.width);
    flipped += s.flipped;
    differs |= s.pixels != a.pixels;
  }
  EXPECT_GT(offsets.size(), 4u);
  EXPECT_EQ(crops, (std::set<int>{48, 42, 36, 32}));  // 1, .875, .75, .66 of 48
  EXPECT_GT(flipped, 5);
  EXPECT_LT(flipped, 35);
  EXPECT_TRUE(differs);
  // Without flips (--no-flip): the same offsets and crops seed by seed, never a flip, and the very
  // samples the seed's recipe drew unflipped.
  SampleOptions unflipped = o;
  unflipped.flip = false;
  int same_pixels = 0;
  for (uint64_t seed = 0; seed < 40; ++seed) {
    const Sample with = LoadSample(clip, o, seed), without = LoadSample(clip, unflipped, seed);
    EXPECT_FALSE(without.flipped);
    EXPECT_EQ(without.first_frame, with.first_frame);
    EXPECT_EQ(without.crop, with.crop);
    if (!with.flipped) {
      EXPECT_EQ(without.pixels, with.pixels);
      ++same_pixels;
    }
  }
  EXPECT_EQ(same_pixels, 40 - flipped);
  // Evaluation: centred window, whole square, no flip; the seed does not matter.
  o.augment = false;
  const Sample e1 = LoadSample(clip, o, 1), e2 = LoadSample(clip, o, 99);
  EXPECT_EQ(e1.pixels, e2.pixels);
  EXPECT_EQ(e1.first_frame, 5);
  EXPECT_EQ(e1.crop, cv::Rect(0, 0, 48, 48));
  EXPECT_FALSE(e1.flipped);
  // Evaluation's mirror option: the same window and crop, mirrored left to right.
  o.mirror = true;
  const Sample em = LoadSample(clip, o, 7);
  EXPECT_TRUE(em.flipped);
  EXPECT_EQ(em.crop, e1.crop);
  const int side = o.input_size;
  for (int t = 0; t < o.frames; t += 7)
    for (int y = 0; y < side; y += 3)
      for (int x = 0; x < side; ++x)
        ASSERT_FLOAT_EQ(em.pixels[(t * side + y) * side + x], e1.pixels[(t * side + y) * side + side - 1 - x])
            << t << " " << y;
}

TEST_F(DatasetTest, ExplicitWindowStartsAreEvenlySpacedAndRespected) {
  EXPECT_EQ(EvenWindowStarts(60, 30, 1), (std::vector<int>{15}));  // the centred window
  EXPECT_EQ(EvenWindowStarts(60, 30, 2), (std::vector<int>{0, 30}));
  EXPECT_EQ(EvenWindowStarts(60, 30, 3), (std::vector<int>{0, 15, 30}));
  EXPECT_EQ(EvenWindowStarts(40, 30, 4), (std::vector<int>{0, 3, 7, 10}));
  // Fewer starts than windows: each start once ({0, 0, 0} and {0, 1, 1} weighted one window
  // more than the others in eval's mean).
  EXPECT_EQ(EvenWindowStarts(30, 30, 3), (std::vector<int>{0}));
  EXPECT_EQ(EvenWindowStarts(31, 30, 3), (std::vector<int>{0, 1}));
  EXPECT_EQ(EvenWindowStarts(32, 30, 3), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(EvenWindowStarts(33, 30, 10), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(EvenWindowStarts(31, 30, 2), (std::vector<int>{0, 1}));
  EXPECT_THROW(EvenWindowStarts(60, 30, 0), std::invalid_argument);
  EXPECT_THROW(EvenWindowStarts(20, 30, 1), std::invalid_argument);
  // The dataset's clips have 40 frames: a window set at the centred start is the centred window;
  // another start gives other frames, even when augmenting; one past the end is an error.
  const ClipInfo clip = ReadDataset(*dir_).clips[0];
  SampleOptions o;
  o.frames = 30;
  o.input_size = 32;
  const Sample centred = LoadSample(clip, o, 0);
  o.first_frame = 5;
  EXPECT_EQ(LoadSample(clip, o, 0).pixels, centred.pixels);
  o.first_frame = 0;
  const Sample first = LoadSample(clip, o, 0);
  EXPECT_EQ(first.first_frame, 0);
  EXPECT_NE(first.pixels, centred.pixels);
  o.augment = true;
  for (uint64_t seed = 0; seed < 5; ++seed) EXPECT_EQ(LoadSample(clip, o, seed).first_frame, 0);
  o.first_frame = 11;
  try {
    LoadSample(clip, o, 0);
    ADD_FAILURE() << "a window past the clip's end was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("40"), std::string::npos) << e.what();
  }
}

TEST(MakeSample, FlipMirrorsTheFrames) {
  // A horizontal ramp: the flipped sample is the mirror image of the unflipped one.
  std::vector<cv::Mat> frames;
  for (int t = 0; t < 4; ++t) {
    cv::Mat f(16, 16, CV_8UC1);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) f.at<uint8_t>(y, x) = static_cast<uint8_t>(10 * x + t);
    frames.push_back(f);
  }
  SampleOptions o;
  o.frames = 4;
  o.input_size = 16;
  o.augment = true;
  o.crop_scales = {1.0};
  Sample plain, mirrored;
  for (uint64_t seed = 0; seed < 20 && (plain.pixels.empty() || mirrored.pixels.empty()); ++seed) {
    std::mt19937_64 rng(seed);
    Sample s = MakeSample(frames, o, rng);
    (s.flipped ? mirrored : plain) = s;
  }
  ASSERT_FALSE(plain.pixels.empty());
  ASSERT_FALSE(mirrored.pixels.empty());
  for (int t = 0; t < 4; ++t)
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x)
        EXPECT_FLOAT_EQ(mirrored.pixels[(t * 16 + y) * 16 + x], plain.pixels[(t * 16 + y) * 16 + 15 - x]);
  EXPECT_LT(plain.pixels[0], plain.pixels[15]);  // the ramp rises left to right unflipped
}

// A flag held at column 8 of 64 x 48 frames (a 16-px margin either side of the centred square),
// flying right: ripples that grow toward the fly end and travel there, on a still grey.
std::vector<cv::Mat> FlagFlyingRight(int frames) {
  std::vector<cv::Mat> out;
  for (int t = 0; t < frames; ++t) {
    cv::Mat f(48, 64, CV_8UC1, cv::Scalar::all(100));
    for (int y = 0; y < 48; ++y) {
      for (int x = 24; x < 56; ++x) {
        const double amplitude = 60.0 * (x - 24) / 32.0;
        f.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(100 + amplitude * std::sin(0.4 * x - 2 * M_PI * 3 * t / frames));
      }
    }
    out.push_back(f);
  }
  return out;
}

// A toy dataset that cannot be written (a full disk part way) leaves no temporary folder behind
// (each failed run left one).
TEST_F(DatasetTest, AToyDatasetThatCannotBeWrittenLeavesNoTemporaryFolder) {
  const fs::path dir = Copy("toy_full_disk");
  ToyDatasetOptions o;
  o.clips = 2;
  o.frames = 3;
  o.size = 64;
  {
    const ScopedFileSizeLimit full(200);  // a 64-px frame takes some kilobytes
    EXPECT_ANY_THROW(WriteToyDataset(dir, o));
  }
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

// A smaller toy dataset over a larger one: the old index and the examples beyond the new count
// go (a run stopped half way used to leave the old index over both runs' examples).
TEST_F(DatasetTest, AToyDatasetOverAnotherReplacesItWhole) {
  const fs::path copy = Copy("toy_over");
  ToyDatasetOptions o;
  o.clips = 3;
  o.frames = 4;
  o.size = 16;
  o.seed = 9;
  std::vector<std::pair<int, int>> reports;
  WriteToyDataset(copy, o, [&](int done, int total) { reports.emplace_back(done, total); });
  EXPECT_EQ(reports, (std::vector<std::pair<int, int>>{{0, 3}, {1, 3}, {2, 3}, {3, 3}}));
  const Dataset d = ReadDataset(copy);
  EXPECT_EQ(d.clips.size(), 3u);
  EXPECT_FALSE(fs::exists(copy / "toy-00003"));
  EXPECT_FALSE(fs::exists(copy / "toy-00009"));
  for (const ClipInfo& c : d.clips) EXPECT_EQ(c.num_frames, 4);
  // A stopped run's example being written, numbered past this run's: it stayed for good.
  fs::create_directories(copy / ".toy-00089.tmp");
  std::ofstream(copy / ".toy-00089.tmp" / "000.jpg") << "half";
  fs::create_directories(copy / ".toy-notes");  // not one: stays
  WriteToyDataset(copy, o);
  EXPECT_FALSE(fs::exists(copy / ".toy-00089.tmp"));
  EXPECT_TRUE(fs::exists(copy / ".toy-notes"));

  // Over a dataset of another kind (a FlagSim one's index, its settings in the header): refused,
  // its index kept (it was removed and replaced by a toy one).
  nlohmann::json index;
  {
    std::ifstream in(copy / "index.json");
    index = nlohmann::json::parse(in);
  }
  index["kind"] = "flag";
  {
    std::ofstream out(copy / "index.json");
    out << index.dump();
  }
  try {
    WriteToyDataset(copy, o);
    ADD_FAILURE() << "a flag dataset was written over";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((copy / "index.json").string() + " is not a toy dataset's index"),
              std::string::npos)
        << e.what();
  }
  std::ifstream in(copy / "index.json");
  EXPECT_EQ(nlohmann::json::parse(in)["kind"], "flag");
}

TEST(MakeSample, FlagFliesTurnsAFlagFlyingLeftToFlyRight) {
  // As a model trained without flips reads a flag: mirrored clips (mirror_clip, a flag flying
  // left) come back to the as-filmed sample, by --flag-flies left always, by auto from the motion.
  SampleOptions o;
  o.frames = 30;
  o.input_size = 32;
  std::mt19937_64 rng(0);
  const std::vector<cv::Mat> frames = FlagFlyingRight(30);
  const Sample filmed = MakeSample(frames, o, rng);
  EXPECT_FALSE(filmed.flipped);
  EXPECT_FALSE(filmed.turned);

  o.mirror_clip = true;
  const Sample left = MakeSample(frames, o, rng);
  EXPECT_TRUE(left.flipped);
  EXPECT_NE(left.pixels, filmed.pixels);
  for (const FlagFlies f : {FlagFlies::kLeft, FlagFlies::kAuto}) {
    SCOPED_TRACE(FlagFliesName(f));
    o.flag_flies = f;
    const Sample turned = MakeSample(frames, o, rng);
    EXPECT_TRUE(turned.turned);
    EXPECT_FALSE(turned.flipped);
    EXPECT_EQ(turned.pixels, filmed.pixels);
    if (f == FlagFlies::kAuto) {
      EXPECT_LT(turned.fly_score, 0);
    }
  }
  // Auto leaves a flag that flies right as it is, scoring the opposite of its mirror image.
  o.mirror_clip = false;
  const Sample kept = MakeSample(frames, o, rng);
  EXPECT_FALSE(kept.turned);
  EXPECT_GT(kept.fly_score, 0);
  EXPECT_EQ(kept.pixels, filmed.pixels);
  // Evaluation's mirror averaging still mirrors the turned clip.
  o.mirror_clip = true;
  o.mirror = true;
  const Sample both = MakeSample(frames, o, rng);
  EXPECT_TRUE(both.turned);
  EXPECT_TRUE(both.flipped);
  EXPECT_EQ(both.pixels, left.pixels);
}

// A smooth random texture, as a flag's print and shading look to the flow at 64 px.
cv::Mat Texture(int side, uint64_t seed) {
  cv::Mat noise(side, side, CV_32F);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.5);
  cv::normalize(noise, noise, 20, 235, cv::NORM_MINMAX);
  cv::Mat out;
  noise.convertTo(out, CV_8U);
  return out;
}

// `image` moved by (dx, dy) [px] (bilinear; edges reflected).
cv::Mat Shifted(const cv::Mat& image, double dx, double dy) {
  const cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(image, out, m, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

// Mean of one channel of a CV_32FC2 flow over its interior (a border of 8 px left out: there the
// reflected edge does not move as the texture does).
double InteriorMean(const cv::Mat& flow, int channel) {
  cv::Mat c;
  cv::extractChannel(flow(cv::Rect(8, 8, flow.cols - 16, flow.rows - 16)), c, channel);
  return cv::mean(c)[0];
}

TEST(FrameFlow, ReadsAKnownShift) {
  const cv::Mat a = Texture(64, 3);
  for (const cv::Point2d shift : {cv::Point2d(0, 0), cv::Point2d(0.4, -0.3), cv::Point2d(1.5, 0.8), cv::Point2d(-2.5, 0)}) {
    const cv::Mat flow = FrameFlow(a, Shifted(a, shift.x, shift.y));
    ASSERT_EQ(flow.type(), CV_32FC2);
    ASSERT_EQ(flow.size(), a.size());
    EXPECT_NEAR(InteriorMean(flow, 0), shift.x, 0.1) << shift;
    EXPECT_NEAR(InteriorMean(flow, 1), shift.y, 0.1) << shift;
  }
  // A window's flows are the same flow on a 1/256 px grid.
  const cv::Mat b = Shifted(a, 0.7, 0.2);
  const cv::Mat f = FrameFlow(a, b), grid = WindowFlows({a, b})[0];
  EXPECT_LE(cv::norm(grid, f, cv::NORM_INF), 0.5 / kFlowSteps + 1e-6);
  cv::Mat steps = grid * kFlowSteps, rounded;
  steps.convertTo(rounded, CV_16SC2);
  rounded.convertTo(rounded, CV_32FC2);
  EXPECT_EQ(cv::norm(steps, rounded, cv::NORM_INF), 0.0);
  // Computed on a finer image and brought to the input's size, the flow keeps the input's units:
  // the same texture at twice the size, shifted twice as far, reads the same shift.
  cv::Mat big;
  cv::resize(a, big, cv::Size(128, 128), 0, 0, cv::INTER_LINEAR);
  const std::vector<cv::Mat> fine = WindowFlows({big, Shifted(big, 1.6, -1.0)}, cv::Rect(0, 0, 128, 128), 128, 64);
  ASSERT_EQ(fine[0].size(), cv::Size(64, 64));
  EXPECT_NEAR(InteriorMean(fine[0], 0), 0.8, 0.1);
  EXPECT_NEAR(InteriorMean(fine[0], 1), -0.5, 0.1);
  EXPECT_THROW(FrameFlow(a, cv::Mat(32, 32, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(FrameFlow(a, cv::Mat(64, 64, CV_32F, cv::Scalar(0))), std::invalid_argument);
}

TEST(MakeSample, FlowChannelsFollowTheMotionAndTheFlip) {
  // A texture running right at 1 px and down at 0.5 px per frame, seen whole at its own size.
  const cv::Mat texture = Texture(48, 5);
  std::vector<cv::Mat> frames;
  for (int t = 0; t < 6; ++t) frames.push_back(Shifted(texture, 1.0 * t, 0.5 * t));
  SampleOptions o;
  o.frames = 6;
  o.input_size = 48;
  o.flow = true;
  std::mt19937_64 rng(0);
  const Sample s = MakeSample(frames, o, rng);
  ASSERT_EQ(s.channels, 3);
  const size_t plane = 48 * 48, grey = 6 * plane;
  ASSERT_EQ(s.pixels.size(), 3 * grey);
  // Channel 0 is the grey sample without flow, unchanged.
  SampleOptions no_flow = o;
  no_flow.flow = false;
  const Sample g = MakeSample(frames, no_flow, rng);
  EXPECT_EQ(g.channels, 1);
  EXPECT_TRUE(std::equal(g.pixels.begin(), g.pixels.end(), s.pixels.begin()));
  auto flow_at = [](const Sample& sample, int channel, int t) {
    return cv::Mat(48, 48, CV_32F, const_cast<float*>(sample.pixels.data()) + (6 * channel + t) * 48 * 48).clone();
  };
  const cv::Rect inner(8, 8, 32, 32);
  for (int t = 0; t < 6; ++t) {
    EXPECT_NEAR(cv::mean(flow_at(s, 1, t)(inner))[0], 1.0, 0.1) << "x, frame " << t;
    EXPECT_NEAR(cv::mean(flow_at(s, 2, t)(inner))[0], 0.5, 0.1) << "y, frame " << t;
  }
  // Frame 0 has no flow arriving at it: it repeats frame 1's.
  EXPECT_EQ(cv::norm(flow_at(s, 1, 0), flow_at(s, 1, 1), cv::NORM_INF), 0.0);
  // Mirrored: the same flow field mirrored, its x component negated (the motion runs left).
  o.mirror = true;
  const Sample m = MakeSample(frames, o, rng);
  ASSERT_TRUE(m.flipped);
  for (int t = 0; t < 6; ++t) {
    cv::Mat x = flow_at(s, 1, t), y = flow_at(s, 2, t);
    cv::flip(x, x, 1);
    cv::flip(y, y, 1);
    EXPECT_EQ(cv::norm(flow_at(m, 1, t), -x, cv::NORM_INF), 0.0) << t;
    EXPECT_EQ(cv::norm(flow_at(m, 2, t), y, cv::NORM_INF), 0.0) << t;
  }
  // Flows handed in are used as they are, and must match the window.
  const std::vector<cv::Mat> given = WindowFlows(frames);
  o.mirror = false;
  EXPECT_EQ(MakeSample(frames, o, rng, &given).pixels, s.pixels);
  const std::vector<cv::Mat> short_by_one(given.begin() + 1, given.end());
  EXPECT_THROW(MakeSample(frames, o, rng, &short_by_one), std::invalid_argument);
}


// FlagSim's red and green (sRGB) as OpenCV's BGR: 74 and 79 of 255 in grey.
const cv::Vec3b kRed(46, 16, 200), kGreen(61, 122, 0);

// Frames whose lower half is a red field and a green one with their edge swinging 4 px left and
// right, under a still grey ramp (the sky) that sets the clip's contrast, as YCrCb (`colour`) or
// grey, as LoadFrames gives them.
std::vector<cv::Mat> RedGreenEdgeFrames(bool colour) {
  std::vector<cv::Mat> frames;
  for (int t = 0; t < 16; ++t) {
    cv::Mat bgr(32, 32, CV_8UC3);
    const int edge = 16 + static_cast<int>(std::lround(4 * std::sin(2 * M_PI * t / 8.0)));
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const uint8_t sky = static_cast<uint8_t>(40 + 6 * x);
        bgr.at<cv::Vec3b>(y, x) = y < 16 ? cv::Vec3b(sky, sky, sky) : (x < edge ? kRed : kGreen);
      }
    }
    cv::Mat out;
    cv::cvtColor(bgr, out, colour ? cv::COLOR_BGR2YCrCb : cv::COLOR_BGR2GRAY);
    frames.push_back(out);
  }
  return frames;
}

// Temporal standard deviation of channel `c` of a sample over a window of pixels, the largest.
double LargestTemporalStd(const Sample& s, int c, int frames, int side, const cv::Rect& where) {
  double largest = 0;
  for (int y = where.y; y < where.y + where.height; ++y) {
    for (int x = where.x; x < where.x + where.width; ++x) {
      double sum = 0, sum2 = 0;
      for (int t = 0; t < frames; ++t) {
        const double v = s.pixels[((static_cast<size_t>(c) * frames + t) * side + y) * side + x];
        sum += v;
        sum2 += v * v;
      }
      largest = std::max(largest, std::sqrt(std::max(sum2 / frames - sum * sum / frames / frames, 0.0)));
    }
  }
  return largest;
}

TEST(CameraFramesForModel, GreyForGreyModelsYCrCbForColourOnesAndNoColourFromGrey) {
  cv::Mat bgr(12, 12, CV_8UC3);
  cv::randu(bgr, 0, 256);
  cv::Mat grey(12, 12, CV_8UC1);
  cv::randu(grey, 0, 256);
  // A grey model: grey frames pass as they are (no copy), BGR ones become their grey.
  const std::vector<cv::Mat> g = CameraFramesForModel({grey, bgr}, false);
  ASSERT_EQ(g.size(), 2u);
  EXPECT_EQ(g[0].data, grey.data);
  cv::Mat expected;
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2GRAY);
  ASSERT_EQ(g[1].type(), FrameType(false));
  EXPECT_EQ(cv::norm(g[1], expected, cv::NORM_INF), 0.0);
  // A colour model: BGR becomes YCrCb, as LoadFrames gives colour frames.
  const std::vector<cv::Mat> c = CameraFramesForModel({bgr}, true);
  ASSERT_EQ(c[0].type(), FrameType(true));
  cv::cvtColor(bgr, expected, cv::COLOR_BGR2YCrCb);
  EXPECT_EQ(cv::norm(c[0], expected, cv::NORM_INF), 0.0);
  // Grey frames for a colour model are refused with the parameter that fixes it.
  try {
    CameraFramesForModel({grey}, true);
    FAIL() << "grey frames given to a colour model";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("~colour"), std::string::npos) << e.what();
  }
  EXPECT_THROW(CameraFramesForModel({cv::Mat(4, 4, CV_16UC1)}, false), std::invalid_argument);
}

TEST(MakeSample, ColourChannelsSeeAnEdgeTheGreyHides) {
  SampleOptions o;
  o.frames = 16;
  o.input_size = 32;
  std::mt19937_64 rng(0);
  const Sample grey = MakeSample(RedGreenEdgeFrames(false), o, rng);
  o.colour = true;
  const Sample colour = MakeSample(RedGreenEdgeFrames(true), o, rng);
  ASSERT_EQ(colour.channels, 3);
  ASSERT_EQ(colour.pixels.size(), 3u * 16 * 32 * 32);
  // The edge's swing in units of each clip's own contrast: barely a flicker in grey, a full
  // swing in Cr (red against green).
  const cv::Rect edge(12, 16, 9, 16);
  const double in_grey = LargestTemporalStd(grey, 0, 16, 32, edge);
  const double in_cr = LargestTemporalStd(colour, 1, 16, 32, edge);
  EXPECT_LT(in_grey, 0.15);
  EXPECT_GT(in_cr, 5 * in_grey) << "grey " << in_grey << ", Cr " << in_cr;
  // Y is the grey: channel 0 follows the grey sample's pixels (one scale and offset apart).
  const size_t n = 16 * 32 * 32;
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < n; ++i) {
    sxy += grey.pixels[i] * colour.pixels[i];
    sxx += grey.pixels[i] * grey.pixels[i];
    syy += colour.pixels[i] * colour.pixels[i];
  }
  EXPECT_GT(sxy / std::sqrt(sxx * syy), 0.999);
  // All three channels together have zero mean each and unit std jointly.
  double joint = 0;
  for (int c = 0; c < 3; ++c) {
    const double mean = std::accumulate(colour.pixels.begin() + c * n, colour.pixels.begin() + (c + 1) * n, 0.0) / n;
    EXPECT_NEAR(mean, 0.0, 1e-4) << c;
    for (size_t i = c * n; i < (c + 1) * n; ++i) joint += colour.pixels[i] * colour.pixels[i];
  }
  EXPECT_NEAR(joint / (3 * n), 1.0, 1e-3);
  // The mirror image mirrors every channel.
  o.mirror = true;
  const Sample mirrored = MakeSample(RedGreenEdgeFrames(true), o, rng);
  for (int c = 0; c < 3; ++c)
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x)
        ASSERT_FLOAT_EQ(mirrored.pixels[((c * 16 + 5) * 32 + y) * 32 + x], colour.pixels[((c * 16 + 5) * 32 + y) * 32 + 31 - x]);
  // Grey frames for a colour sample, and colour with flow, are refused.
  EXPECT_THROW(MakeSample(RedGreenEdgeFrames(false), o, rng), std::invalid_argument);
  o.mirror = false;
  o.flow = true;
  EXPECT_THROW(MakeSample(RedGreenEdgeFrames(true), o, rng), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::learn
