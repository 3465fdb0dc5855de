// The learned fly-direction judge: its motion map (unit mean, mirrored with the clip, blind to
// contrast), the exact antisymmetry of its score, its file round trip and refusals, and that
// training on flags held at the left, wherever they hang, teaches it the side of held-out flags
// and of their mirror images.
#include "learn/fly_judge.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "learn/fly_judge_train.h"
#include "learn/model_config.h"
#include "learn/test_mirrored_frames.h"

namespace clothwind::learn {
namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 30;
constexpr int kSide = 64;

// A flag held at column x0 and flying right over `length` columns, rows y0 .. y0 + height: at
// column x its ripples have amplitude gain * ((x - x0) / length)^power, travelling along it at
// wavenumber k, on a grey 90 background with Gaussian noise of `noise` grey levels.
struct FlagClip {
  int x0 = 8, length = 40, y0 = 16, height = 30;
  double gain = 60, power = 1, k = 0.4, omega = 2 * M_PI * 3 / kFrames, noise = 0;
};

std::vector<cv::Mat> Clip(const FlagClip& c, std::mt19937_64& rng) {
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<cv::Mat> frames;
  for (int t = 0; t < kFrames; ++t) {
    cv::Mat f(kSide, kSide, CV_8UC1);
    for (int y = 0; y < kSide; ++y) {
      for (int x = 0; x < kSide; ++x) {
        double v = 90;
        const double along = static_cast<double>(x - c.x0) / c.length;
        if (y >= c.y0 && y < c.y0 + c.height && along >= 0 && along <= 1) {
          v = 140 + c.gain * std::pow(along, c.power) * std::sin(c.k * x - c.omega * t + 0.1 * y);
        }
        if (c.noise > 0) v += c.noise * noise(rng);
        f.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(v);
      }
    }
    frames.push_back(f);
  }
  return frames;
}

// A judge with random weights (H hidden units).
FlyJudge RandomJudge(int hidden, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> n(0.0f, 0.3f);
  Eigen::MatrixXf w1(hidden, kMotionMapGrid * kMotionMapGrid);
  Eigen::VectorXf b1(hidden), w2(hidden);
  for (int i = 0; i < w1.size(); ++i) w1.data()[i] = n(rng);
  for (int i = 0; i < hidden; ++i) {
    b1[i] = n(rng);
    w2[i] = n(rng);
  }
  return FlyJudge(w1, b1, w2, n(rng));
}

TEST(MotionMapTest, AveragesOneMirrorsWithTheClipAndIgnoresContrast) {
  std::mt19937_64 rng(1);
  const std::vector<cv::Mat> clip = Clip(FlagClip{}, rng);
  const cv::Mat map = MotionMap(clip);
  ASSERT_EQ(map.type(), CV_32FC1);
  ASSERT_EQ(map.rows, kMotionMapGrid);
  ASSERT_EQ(map.cols, kMotionMapGrid);
  EXPECT_NEAR(cv::mean(map)[0], 1.0, 1e-5);
  // The flag's right (fly) end moves most; left of the hoist nothing moves.
  EXPECT_GT(map.at<float>(8, 11), 2 * map.at<float>(8, 4));
  EXPECT_FLOAT_EQ(map.at<float>(8, 0), 0.0f);

  cv::Mat flipped;
  cv::flip(map, flipped, 1);
  EXPECT_LT(cv::norm(MotionMap(Mirrored(clip)), flipped, cv::NORM_INF), 1e-5);

  FlagClip half;
  half.gain = 30;  // half the contrast: the same shape, up to 8-bit rounding
  EXPECT_LT(cv::norm(MotionMap(Clip(half, rng)), map, cv::NORM_INF), 0.05);
}

TEST(MotionMapTest, ResizesAnySideToItsOwn) {
  std::mt19937_64 rng(2);
  const std::vector<cv::Mat> clip = Clip(FlagClip{}, rng);
  std::vector<cv::Mat> big;
  for (const cv::Mat& f : clip) {
    cv::Mat b;
    cv::resize(f, b, cv::Size(2 * kSide, 2 * kSide), 0, 0, cv::INTER_NEAREST);
    big.push_back(b);
  }
  EXPECT_LT(cv::norm(MotionMap(big), MotionMap(clip), cv::NORM_INF), 1e-4);
}

TEST(MotionMapTest, StillClipHasNoShapeAndTheJudgeTellsNothing) {
  const std::vector<cv::Mat> still(kFrames, cv::Mat(kSide, kSide, CV_8UC1, cv::Scalar(120)));
  EXPECT_EQ(cv::countNonZero(MotionMap(still)), 0);
  double score = 1;
  EXPECT_EQ(RandomJudge(8, 3).Judge(still, &score), std::nullopt);
  EXPECT_EQ(score, 0.0);
}

TEST(FlyJudgeTest, ScoresInsideTheMarginDecideNothingAndTheMarginTravelsWithTheCard) {
  FlyJudge judge = RandomJudge(16, 4);
  std::mt19937_64 rng(5);
  const std::vector<cv::Mat> clip = Clip(FlagClip{}, rng);
  double score = 0;
  const std::optional<FlyDirection> way = judge.Judge(clip, &score);
  ASSERT_TRUE(way.has_value());
  ASSERT_GT(std::abs(score), 0.0);
  judge.set_margin(std::abs(score) * 1.01);  // just beyond this clip's score: it tells nothing
  EXPECT_EQ(judge.Judge(clip), std::nullopt);
  EXPECT_EQ(judge.Judge(Mirrored(clip)), std::nullopt);
  judge.set_margin(std::abs(score) * 0.99);
  EXPECT_EQ(judge.Judge(clip), way);
  // Damaged weights (a NaN) tell nothing rather than "right".
  const FlyJudge broken(judge.hidden_weights(), judge.hidden_bias(), judge.output_weights(), std::nanf(""));
  double nan_score = 0;
  EXPECT_EQ(broken.Judge(clip, &nan_score), std::nullopt);
  EXPECT_TRUE(std::isnan(nan_score));
  EXPECT_THROW(judge.set_margin(-1), std::invalid_argument);
  EXPECT_THROW(judge.set_margin(std::nan("")), std::invalid_argument);
  // Saved and loaded with its card; a card's bad margin is refused naming it.
  const fs::path dir = fs::temp_directory_path() / ("fly_judge_margin_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  judge.Save(dir / "judge.pt");
  EXPECT_DOUBLE_EQ(FlyJudge::Load(dir / "judge.pt").margin(), judge.margin());
  nlohmann::json card = ReadJson(dir / "judge.json");
  card["margin"] = -0.5;
  WriteFileAtomically(dir / "judge.json", card.dump());
  try {
    FlyJudge::Load(dir / "judge.pt");
    ADD_FAILURE() << "a negative margin loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("\"margin\""), std::string::npos) << e.what();
  }
  card.erase("margin");  // cards written before margins: 0
  WriteFileAtomically(dir / "judge.json", card.dump());
  EXPECT_EQ(FlyJudge::Load(dir / "judge.pt").margin(), 0.0);
  fs::remove_all(dir);
}

TEST(MotionMapTest, RefusesNamingTheFrame) {
  std::vector<cv::Mat> frames(3, cv::Mat(kSide, kSide, CV_8UC1, cv::Scalar(0)));
  frames[2] = cv::Mat(kSide, kSide, CV_8UC3, cv::Scalar(0, 0, 0));
  try {
    MotionMap(frames);
    FAIL() << "a colour frame was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("frame 2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MotionMap({frames[0]}), std::invalid_argument);
}

TEST(FlyJudgeTest, ScoreIsExactlyAntisymmetricUnderMirroring) {
  const FlyJudge judge = RandomJudge(16, 4);
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 5; ++trial) {
    FlagClip c;
    c.x0 = 2 + trial * 3;
    const std::vector<cv::Mat> clip = Clip(c, rng);
    double right = 0, left = 0;
    const std::optional<FlyDirection> a = judge.Judge(clip, &right), b = judge.Judge(Mirrored(clip), &left);
    EXPECT_NEAR(left, -right, 1e-5 * (1 + std::abs(right)));  // the maps agree to float rounding
    if (std::abs(right) > 1e-3) {
      EXPECT_NE(a, b);
    }
    cv::Mat map = MotionMap(clip), flipped;
    cv::flip(map, flipped, 1);
    EXPECT_EQ(judge.Score(flipped), -judge.Score(map));  // the same two logits, subtracted the other way
  }
}

TEST(FlyJudgeTest, SaveLoadRoundTripKeepsScoresAndCard) {
  const fs::path dir = fs::temp_directory_path() / ("fly_judge_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const FlyJudge judge = RandomJudge(12, 6);
  judge.Save(dir / "judge.pt", {{"data", "synthetic"}});
  const FlyJudge loaded = FlyJudge::Load(dir / "judge.pt");
  EXPECT_EQ(loaded.hidden(), 12);
  EXPECT_EQ((loaded.hidden_weights() - judge.hidden_weights()).cwiseAbs().maxCoeff(), 0.0f);
  EXPECT_EQ(loaded.output_bias(), judge.output_bias());
  std::mt19937_64 rng(7);
  const cv::Mat map = MotionMap(Clip(FlagClip{}, rng));
  EXPECT_EQ(loaded.Score(map), judge.Score(map));
  const nlohmann::json card = ReadJson(dir / "judge.json");
  EXPECT_EQ(card.at("data"), "synthetic");
  EXPECT_EQ(card.at("grid"), kMotionMapGrid);
  // The card train-fly-judge writes loads (a field Load did not know, "shift", made every newly
  // trained judge unloadable).
  FlyJudgeTrainOptions options;
  options.shift = 3;
  judge.Save(dir / "judge.pt", FlyJudgeTrainingCard("/data/flagsim-e5", 3, 30, options, {{"test", {{"count", 1}}}}));
  EXPECT_EQ(FlyJudge::Load(dir / "judge.pt").Score(map), judge.Score(map));
  EXPECT_EQ(ReadJson(dir / "judge.json").at("shift"), 3);

  // A card that disagrees with the weights' shape is refused, naming the weights file.
  WriteFileAtomically(dir / "judge.json", nlohmann::json{{"hidden", 5}, {"grid", 16}, {"side", 64}}.dump());
  try {
    FlyJudge::Load(dir / "judge.pt");
    FAIL() << "a 12-unit file loaded as 5 units";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("judge.pt"), std::string::npos) << e.what();
  }
  // A card asking for more units than training allows is refused before anything is allocated.
  WriteFileAtomically(dir / "judge.json", nlohmann::json{{"hidden", 1000000000}, {"grid", 16}, {"side", 64}}.dump());
  try {
    FlyJudge::Load(dir / "judge.pt");
    FAIL() << "a card of 1e9 hidden units loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("1..4096"), std::string::npos) << e.what();
  }
  WriteFileAtomically(dir / "judge.json", nlohmann::json{{"hidden", 12}, {"grid", 8}, {"side", 64}}.dump());
  EXPECT_THROW(FlyJudge::Load(dir / "judge.pt"), std::runtime_error);
  // A misspelt margin is refused (it ran at margin 0), naming the field.
  WriteFileAtomically(dir / "judge.json",
                      nlohmann::json{{"hidden", 12}, {"grid", 16}, {"side", 64}, {"margn", 1e9}}.dump());
  try {
    FlyJudge::Load(dir / "judge.pt");
    FAIL() << "a card with \"margn\" loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("judge.json: unknown field \"margn\""), std::string::npos) << e.what();
  }
  // A field of the wrong kind is refused as such, naming the card (not a bare JSON type error).
  WriteFileAtomically(dir / "judge.json", nlohmann::json{{"hidden", 12}, {"grid", "16"}, {"side", 64}}.dump());
  try {
    FlyJudge::Load(dir / "judge.pt");
    FAIL() << "a card with \"grid\": \"16\" loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("judge.json"), std::string::npos) << e.what();
  }
  fs::remove(dir / "judge.json");
  try {
    FlyJudge::Load(dir / "judge.pt");
    FAIL() << "loaded without its card";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("judge.json"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(FlyJudgeTest, WeightsBesideAnotherJudgesCardAreRefusedNamingTheField) {
  // A train-fly-judge stopped between the pair's two renames left the new weights beside the old
  // card, and the judge loaded with the other's margin and provenance, silently. The card is kept
  // inside the weights too; the margin alone may be set on the card.
  const fs::path dir = fs::temp_directory_path() / ("fly_judge_pair_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  RandomJudge(12, 6).Save(dir / "judge.pt", {{"data", "synthetic"}, {"seed", 1}});
  const std::string old_card = ReadJson(dir / "judge.json").dump();
  RandomJudge(12, 7).Save(dir / "judge.pt", {{"data", "synthetic"}, {"seed", 7}});
  EXPECT_NO_THROW(FlyJudge::Load(dir / "judge.pt"));
  WriteFileAtomically(dir / "judge.json", old_card);  // the old card beside the new weights
  try {
    FlyJudge::Load(dir / "judge.pt");
    FAIL() << "new weights loaded with the old card";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("judge.json: field \"seed\" is 1, but " + (dir / "judge.pt").string() +
                                         " was saved with 7"),
              std::string::npos)
        << e.what();
  }
  nlohmann::json card = ReadJson(dir / "judge.json");
  card["seed"] = 7;
  card["margin"] = 2.5;  // set by hand: allowed
  WriteFileAtomically(dir / "judge.json", card.dump());
  EXPECT_EQ(FlyJudge::Load(dir / "judge.pt").margin(), 2.5);
  fs::remove_all(dir);
}

TEST(FlyJudgeTest, RefusesWeightsOfTheWrongShape) {
  EXPECT_THROW(FlyJudge(Eigen::MatrixXf::Zero(4, 10), Eigen::VectorXf::Zero(4), Eigen::VectorXf::Zero(4), 0),
               std::invalid_argument);
  EXPECT_THROW(FlyJudge(Eigen::MatrixXf::Zero(4, 256), Eigen::VectorXf::Zero(3), Eigen::VectorXf::Zero(4), 0),
               std::invalid_argument);
}

// Where flags are drawn from: hoist column x0, length, top row y0 and height [px of 64], and the
// power of their growth along the flag.
struct FlagRanges {
  int x0_low, x0_high, length_low, length_high, y0_low, y0_high, height_low, height_high;
  double power_low, power_high;
};

// `count` flags held at the left, drawn from `ranges` (gain, wave and noise as every test's),
// slid `offset` px right (negative: left), as motion maps.
MotionMaps DrawFlags(int count, const FlagRanges& r, int offset, std::mt19937_64& rng) {
  std::uniform_int_distribution<int> x0(r.x0_low, r.x0_high), length(r.length_low, r.length_high),
      y0(r.y0_low, r.y0_high), height(r.height_low, r.height_high);
  std::uniform_real_distribution<double> gain(20, 70), power(r.power_low, r.power_high), k(-0.6, 0.6), noise(0, 4);
  MotionMaps out;
  for (int i = 0; i < count; ++i) {
    FlagClip c;
    c.x0 = x0(rng) + offset;
    c.length = length(rng);
    c.y0 = y0(rng);
    c.height = height(rng);
    c.gain = gain(rng);
    c.power = power(rng);
    c.k = k(rng);
    c.noise = noise(rng);
    out.maps.push_back(MotionMap(Clip(c, rng)));
    out.wind_speeds.push_back(c.gain / 7);  // any label: only the bands read it
  }
  return out;
}

// Flags held at the left, of random place, size, shape of growth, wave and noise.
MotionMaps RandomFlags(int count, std::mt19937_64& rng) {
  return DrawFlags(count, {0, 22, 20, 40, 4, 24, 16, 36, 0.5, 2.0}, 0, rng);
}

TEST(FlyJudgeTrainTest, LearnsTheHoistSideOfHeldOutFlagsAndTheirMirrors) {
  std::mt19937_64 rng(8);
  const MotionMaps train = RandomFlags(240, rng), test = RandomFlags(80, rng);
  FlyJudgeTrainOptions o;
  o.hidden = 16;
  o.epochs = 40;
  o.batch = 32;
  o.learning_rate = 3e-3;
  std::vector<double> losses;
  const FlyJudge judge = TrainFlyJudge(train.maps, o, [&](int, int, double loss) { losses.push_back(loss); });
  ASSERT_EQ(static_cast<int>(losses.size()), o.epochs);
  EXPECT_LT(losses.back(), 0.5 * losses.front());

  const FlyJudgeAccuracy untrained = MeasureFlyJudge(RandomJudge(16, 9), test);
  const FlyJudgeAccuracy a = MeasureFlyJudge(judge, test);
  EXPECT_EQ(a.count, 80);
  EXPECT_GE(a.accuracy(), 0.95);
  EXPECT_LT(untrained.accuracy(), 0.8);  // the flags do not make any judge right
  int banded = 0;
  for (const auto& b : a.bands) banded += b.count;
  EXPECT_EQ(banded, a.count);
  // Mirror images are called left exactly as often as the originals right.
  MotionMaps mirrored = test;
  for (cv::Mat& m : mirrored.maps) cv::flip(m, m, 1);
  EXPECT_EQ(MeasureFlyJudge(judge, mirrored).right, a.count - a.right - a.undecided);

  const nlohmann::json j = ToJson(a);
  EXPECT_DOUBLE_EQ(j.at("accuracy").get<double>(), a.accuracy());
  EXPECT_THROW(TrainFlyJudge({}, o), std::invalid_argument);
}

// Flags as FlagSim's cameras frame them, all at one place in the picture (hoist at column
// 10..12 of 64, the fly end near the right edge), of random size, growth, wave and noise; with
// `offset`, the same flags slid that many pixels right (negative: left), cut by the frame's edge,
// as a camera that does not centre the flag shows them.
MotionMaps FramedFlags(int count, int offset, std::mt19937_64& rng) {
  return DrawFlags(count, {10, 12, 34, 40, 15, 17, 28, 32, 1.0, 2.0}, offset, rng);
}

TEST(FlyJudgeTrainTest, ShiftedTrainingJudgesFlagsACameraDoesNotCentre) {
  std::mt19937_64 rng(4);
  const MotionMaps train = FramedFlags(240, 0, rng);
  FlyJudgeTrainOptions o;
  o.hidden = 16;
  o.epochs = 40;
  o.batch = 32;
  o.learning_rate = 3e-3;
  const FlyJudge centred = TrainFlyJudge(train.maps, o);
  o.shift = 3;
  const FlyJudge shifted = TrainFlyJudge(train.maps, o);
  // Framed as in training, both judges know the side.
  const MotionMaps framed = FramedFlags(60, 0, rng);
  EXPECT_GE(MeasureFlyJudge(centred, framed).accuracy(), 0.95);
  EXPECT_GE(MeasureFlyJudge(shifted, framed).accuracy(), 0.95);
  // Filmed 8 px (two cells) further left, the centred judge reads where the motion sits, which
  // now says "left" about as often as not (measured 0.55); the shifted one still reads the flag.
  const MotionMaps slid = FramedFlags(60, -8, rng);
  EXPECT_LT(MeasureFlyJudge(centred, slid).accuracy(), 0.8);
  EXPECT_GE(MeasureFlyJudge(shifted, slid).accuracy(), 0.95);
  EXPECT_THROW(TrainFlyJudge(train.maps, [] { FlyJudgeTrainOptions bad; bad.shift = kMotionMapGrid; return bad; }()),
               std::invalid_argument);
}

TEST(FlyJudgeTrainTest, ShiftMotionMapSlidesInStillnessAndKeepsTheMeanOne) {
  cv::Mat map(kMotionMapGrid, kMotionMapGrid, CV_32FC1);
  for (int y = 0; y < kMotionMapGrid; ++y)
    for (int x = 0; x < kMotionMapGrid; ++x) map.at<float>(y, x) = static_cast<float>(1 + x + 3 * y);
  map /= cv::mean(map)[0];
  const cv::Mat out = ShiftMotionMap(map, 2, -1);  // two cells right, one up
  EXPECT_NEAR(cv::mean(out)[0], 1.0, 1e-6);
  const double scale = out.at<float>(0, 2) / map.at<float>(1, 0);
  for (int y = 0; y < kMotionMapGrid; ++y) {
    for (int x = 0; x < kMotionMapGrid; ++x) {
      if (x < 2 || y == kMotionMapGrid - 1) EXPECT_EQ(out.at<float>(y, x), 0.0f) << x << ", " << y;
      else EXPECT_NEAR(out.at<float>(y, x), scale * map.at<float>(y + 1, x - 2), 1e-5) << x << ", " << y;
    }
  }
  // Eight directions per map, mirrored maps slid the mirrored way.
  MotionMaps one;
  one.maps = {map};
  one.wind_speeds = {3.0};
  const MotionMaps eight = ShiftedMotionMaps(one, 1);
  ASSERT_EQ(eight.maps.size(), 8u);
  EXPECT_EQ(eight.wind_speeds[7], 3.0);
  int k = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx != 0 || dy != 0) {
        EXPECT_EQ(cv::norm(eight.maps[k++], ShiftMotionMap(map, dx, dy), cv::NORM_INF), 0.0);
      }
  EXPECT_THROW(ShiftedMotionMaps(one, 0), std::invalid_argument);
  one.wind_speeds.clear();
  EXPECT_THROW(ShiftedMotionMaps(one, 1), std::invalid_argument);
  cv::Mat mirrored, slid_mirror, mirror_slid;
  cv::flip(map, mirrored, 1);
  cv::flip(ShiftMotionMap(map, 3, 2), mirror_slid, 1);
  slid_mirror = ShiftMotionMap(mirrored, -3, 2);
  EXPECT_EQ(cv::norm(slid_mirror, mirror_slid, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(ShiftMotionMap(cv::Mat::zeros(kMotionMapGrid, kMotionMapGrid, CV_32FC1), 1, 1)), 0);
  EXPECT_THROW(ShiftMotionMap(map, kMotionMapGrid, 0), std::invalid_argument);
  EXPECT_THROW(ShiftMotionMap(cv::Mat::zeros(8, 8, CV_32FC1), 1, 0), std::invalid_argument);
}

TEST(FlyJudgeTrainTest, CollectsOneMapPerWindowOfEachClip) {
  const fs::path dir = fs::temp_directory_path() / ("fly_judge_toy_" + std::to_string(::getpid()));
  ToyDatasetOptions toy;
  toy.clips = 4;
  toy.frames = 40;
  toy.size = 48;
  WriteToyDataset(dir, toy);
  const std::vector<ClipInfo> clips = SelectSplit(ReadDataset(dir), "all");
  int calls = 0;
  const MotionMaps m = CollectMotionMaps(clips, kFrames, 3, [&](int done, int total) {
    ++calls;
    EXPECT_EQ(total, 4);
    EXPECT_EQ(done, calls);
  });
  ASSERT_EQ(m.maps.size(), 12u);
  for (size_t i = 0; i < m.maps.size(); ++i) {
    EXPECT_NEAR(cv::mean(m.maps[i])[0], 1.0, 1e-5);
    EXPECT_EQ(m.wind_speeds[i], clips[i / 3].wind_speed);
  }
  // A clip shorter than a window: refused before any clip is read, naming its label.json.
  std::vector<ClipInfo> short_clips = clips;
  short_clips[2].num_frames = kFrames - 1;
  calls = 0;
  try {
    CollectMotionMaps(short_clips, kFrames, 3, [&](int, int) { ++calls; });
    ADD_FAILURE() << "a short clip was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((clips[2].dir / "label.json").string() + ": field \"num_frames\""),
              std::string::npos) << e.what();
  }
  EXPECT_EQ(calls, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::learn
