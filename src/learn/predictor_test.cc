#include "learn/predictor.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <torch/utils.h>

#include "learn/fly_judge.h"
#include "learn/networks.h"
#include "learn/test_small_sdn.h"

namespace clothwind::learn {
namespace {

namespace fs = std::filesystem;


// A small SDN saved as a training run saves it, in a folder of its own.
class PredictorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("predictor_test_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    WindNet net(SmallSdn());
    SaveWindNet(net, dir_ / "model.pt");
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
};

// 30 frames of 32 x 32 px (the model's input: no resize) whose stripes travel at a frequency
// that grows from left to right, with an amplitude that grows too: neither map is symmetric.
std::vector<cv::Mat> LopsidedClip() {
  std::vector<cv::Mat> frames;
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(32, 32, CV_8UC1);
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        const double hz = 1.0 + 0.25 * x, amplitude = 20 + 3 * x;
        f.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(128 + amplitude * std::sin(2 * M_PI * hz * t / 25.0 - 0.3 * y));
      }
    }
    frames.push_back(f);
  }
  return frames;
}

// A covered lens's 30 frames of 32 px: the dark level 4 and sensor noise of 3 grey levels a pixel.
std::vector<cv::Mat> CoveredLensClip(uint64_t seed) {
  std::vector<cv::Mat> frames;
  cv::RNG rng(seed);
  for (int t = 0; t < 30; ++t) {
    cv::Mat noise(32, 32, CV_32F), f;
    rng.fill(noise, cv::RNG::NORMAL, 4.0, 3.0);
    noise.convertTo(f, CV_8U);
    frames.push_back(f);
  }
  return frames;
}

double MaxAbsDiff(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_INF); }

// A network's output placed below 0 by the label scale is read as calm (0 m/s), one above it as
// it is: the same network and clip, its labels' mean moved down by 100 m/s.
TEST_F(PredictorTest, ASpeedBelowZeroIsReadAsCalm) {
  ModelConfig c = SmallSdn();
  c.label_std = 1.0;
  c.label_mean = 50.0;
  torch::manual_seed(7);  // the same initial weights in both
  WindNet high(c);
  fs::create_directories(dir_ / "high");
  SaveWindNet(high, dir_ / "high" / "model.pt");
  c.label_mean = -50.0;
  torch::manual_seed(7);
  WindNet low(c);
  fs::create_directories(dir_ / "low");
  SaveWindNet(low, dir_ / "low" / "model.pt");
  Predictor read_high(dir_ / "high" / "model.pt", 1, "cpu");
  Predictor read_low(dir_ / "low" / "model.pt", 1, "cpu");
  const Prediction above = read_high.PredictFrames(LopsidedClip());
  const Prediction below = read_low.PredictFrames(LopsidedClip());
  ASSERT_GT(above.speed, 0.0);
  ASSERT_LT(above.speed - 100.0, 0.0) << "the network's output must be within 50 of 0 for this test";
  EXPECT_EQ(below.speed, 0.0);
  EXPECT_NEAR(below.raw_speed, above.raw_speed - 100.0, 1e-9 * above.raw_speed);
  EXPECT_EQ(above.raw_speed, above.speed);
  EXPECT_NEAR(below.speed_std, above.speed_std, 1e-9 * above.speed_std);
}

TEST_F(PredictorTest, AFlyJudgeBesideTheModelThatCannotLoadLeavesTheModelWorking) {
  // Not a torch file, and a card without the judge's fields.
  std::ofstream(dir_ / kFlyJudgeFile) << "not weights";
  std::ofstream(dir_ / "fly_judge.json") << R"({"hidden": 4, "grid": "16", "side": 64})";
  Predictor predictor(dir_ / "model.pt", 1, "cpu");
  EXPECT_EQ(predictor.fly_judge(), nullptr);
  EXPECT_NE(predictor.fly_judge_error().find("fly_judge.json"), std::string::npos) << predictor.fly_judge_error();
  const Prediction p = predictor.PredictFrames(LopsidedClip());
  EXPECT_TRUE(std::isfinite(p.speed) && p.speed_std > 0);

  // A judge that loads replaces the error.
  FlyJudge(Eigen::MatrixXf::Zero(1, kMotionMapGrid * kMotionMapGrid), Eigen::VectorXf::Zero(1),
           Eigen::VectorXf::Zero(1), 0)
      .Save(dir_ / kFlyJudgeFile);
  Predictor with_judge(dir_ / "model.pt", 1, "cpu");
  ASSERT_NE(with_judge.fly_judge(), nullptr);
  EXPECT_EQ(with_judge.fly_judge_error(), "");
  EXPECT_EQ(with_judge.fly_judge_path(), dir_ / kFlyJudgeFile);
}

// A clip's motion is its pixels' mean spread over time, in grey levels, of grey or of Y.
TEST(ClipMotionTest, IsThePixelsMeanTemporalSpread) {
  std::vector<cv::Mat> frozen(30, cv::Mat(8, 8, CV_8UC1, cv::Scalar(77)));
  EXPECT_EQ(ClipMotion(frozen), 0.0);
  // Half the pixels alternate 100/110 (spread 5), the rest stay: a mean of 2.5.
  std::vector<cv::Mat> blinking;
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(8, 8, CV_8UC1, cv::Scalar(100));
    f.rowRange(0, 4).setTo(t % 2 ? 110 : 100);
    blinking.push_back(f);
  }
  EXPECT_NEAR(ClipMotion(blinking), 2.5, 1e-9);
  // Colour (YCrCb): Y alone; Cr and Cb moving are no motion of the picture's brightness.
  std::vector<cv::Mat> ycrcb;
  for (int t = 0; t < 30; ++t) ycrcb.push_back(cv::Mat(8, 8, CV_8UC3, cv::Scalar(100 + (t % 2) * 10, t, 200 - t)));
  EXPECT_NEAR(ClipMotion(ycrcb), 5.0, 1e-9);
}

// A frozen camera's clip (one frame republished) is no measurement: the network answers it with
// a std like a live clip's, so the prediction says it has no motion, and a moving clip does not.
TEST_F(PredictorTest, AClipWithoutMotionIsSaidToHaveNone) {
  Predictor predictor(dir_ / "model.pt", 1, "cpu");
  const std::vector<cv::Mat> moving = LopsidedClip();
  const Prediction live = predictor.PredictFrames(moving);
  EXPECT_FALSE(live.no_motion);
  EXPECT_GT(live.motion, 10.0);
  const std::vector<cv::Mat> frozen(30, moving[7]);
  const Prediction still = predictor.PredictFrames(frozen);
  EXPECT_TRUE(still.no_motion);
  EXPECT_LT(still.motion, 1e-6);  // (0 but for the variance's rounding)
  EXPECT_TRUE(std::isfinite(still.speed));  // the network still answers: the flag says not to trust it
  // A live still scene is not a frozen one: its noise, shrunk and rounded, flickers a few pixels
  // by a grey level (a mean spread of ~0.1), and it is estimated.
  std::vector<cv::Mat> noisy;
  cv::RNG rng(3);
  for (int t = 0; t < 30; ++t) {
    cv::Mat f = moving[7].clone();
    for (int i = 0; i < 64; ++i) f.at<uint8_t>(rng.uniform(0, 32), rng.uniform(0, 32)) += 1;
    noisy.push_back(f);
  }
  const Prediction live_still = predictor.PredictFrames(noisy);
  EXPECT_FALSE(live_still.no_motion) << live_still.motion;
  EXPECT_LT(live_still.motion, 0.3);
}

// A clip's contrast is its picture's spread once pixel noise is blurred away: a scene's shapes
// keep theirs, noise and flicker of one level have none.
TEST(ClipContrastTest, IsTheBlurredPicturesSpreadNotItsNoise) {
  std::vector<cv::Mat> flicker;  // one level, flickering 100/110: much motion, no scene
  for (int t = 0; t < 30; ++t) flicker.push_back(cv::Mat(32, 32, CV_8UC1, cv::Scalar(t % 2 ? 110 : 100)));
  EXPECT_LT(ClipContrast(flicker), 1e-3);  // 0 but for the fit's rounding
  EXPECT_GT(ClipMotion(flicker), 4.0);
  // A dark half against a bright one (a horizon): spread 50, a little less blurred; in an 8 px
  // clip (the smallest sdn_node takes) too, and a small dark patch in a graded sky.
  std::vector<cv::Mat> halves, tiny;
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(32, 32, CV_8UC1, cv::Scalar(50));
    f.colRange(16, 32).setTo(150);
    halves.push_back(f);
    cv::Mat g(8, 8, CV_8UC1, cv::Scalar(200));
    g.rowRange(4, 8).setTo(80);
    tiny.push_back(g);
  }
  EXPECT_GT(ClipContrast(halves), 40.0);
  EXPECT_LE(ClipContrast(halves), 50.0);
  EXPECT_GT(ClipContrast(tiny), 20.0);
  // A covered lens: the dark level 4 and sensor noise of 3 grey levels a pixel.
  const std::vector<cv::Mat> covered = CoveredLensClip(5);
  EXPECT_GT(ClipMotion(covered), 1.0);  // it moves: the motion check alone let it through
  EXPECT_LT(ClipContrast(covered), 0.6);
  // Colour: a red half against a green one of the same grey (Y level) is a scene in its chroma.
  std::vector<cv::Mat> chroma;
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(32, 32, CV_8UC3, cv::Scalar(120, 90, 128));
    f.colRange(16, 32).setTo(cv::Scalar(120, 170, 128));
    chroma.push_back(f);
  }
  EXPECT_GT(ClipContrast(chroma), 30.0);
}

// A covered lens's clip (noise on black) is no measurement either: the network reads some wind
// into the noise, so the prediction says it shows no scene; a clip of a scene does not.
TEST_F(PredictorTest, AClipWithoutASceneIsSaidToHaveNone) {
  Predictor predictor(dir_ / "model.pt", 1, "cpu");
  const Prediction live = predictor.PredictFrames(LopsidedClip());
  EXPECT_FALSE(live.no_scene) << live.contrast;
  EXPECT_GT(live.contrast, 5.0);
  const std::vector<cv::Mat> covered = CoveredLensClip(6);
  const Prediction dark = predictor.PredictFrames(covered);
  EXPECT_TRUE(dark.no_scene) << dark.contrast;
  EXPECT_FALSE(dark.no_motion) << dark.motion;
  EXPECT_TRUE(std::isfinite(dark.speed));  // the network still answers: the flag says not to trust it
}

// The frequency image leaves black the pixels whose peak is too weak to mean anything (still sky
// read as 8.33 Hz was painted like the flag), and colours the rest by frequency.
TEST(FrequencyMapImageTest, WeakPeaksAreBlack) {
  PeakMaps maps;
  maps.power = cv::Mat(4, 4, CV_32F, cv::Scalar(100.0f));
  maps.power.row(0).setTo(0.5f);  // 0.5 % of the strongest
  maps.frequency = cv::Mat(4, 4, CV_32F, cv::Scalar(3.0f));
  const cv::Mat image = FrequencyMapImage(maps, 12.5);
  ASSERT_EQ(image.type(), CV_8UC3);
  EXPECT_EQ(image.at<cv::Vec3b>(0, 2), cv::Vec3b(0, 0, 0));
  const cv::Vec3b lit = image.at<cv::Vec3b>(2, 2);
  EXPECT_NE(lit, cv::Vec3b(0, 0, 0));
  EXPECT_EQ(lit, ColourMapped(maps.frequency, 0, 12.5, cv::COLORMAP_JET).at<cv::Vec3b>(2, 2));
}

TEST_F(PredictorTest, MapsOfAClipTurnedRoundShowTheCamerasPicture) {
  Predictor predictor(dir_ / "model.pt", 1, "cpu");
  const std::vector<cv::Mat> clip = LopsidedClip();
  PeakMaps filmed, turned;
  predictor.set_flag_flies(FlagFlies::kRight);
  EXPECT_FALSE(predictor.PredictFrames(clip, &filmed).turned);
  predictor.set_flag_flies(FlagFlies::kLeft);
  EXPECT_TRUE(predictor.PredictFrames(clip, &turned).turned);
  ASSERT_EQ(filmed.frequency.size(), cv::Size(32, 32));
  // The maps are lopsided, so a mirror image would differ...
  cv::Mat mirrored;
  cv::flip(filmed.frequency, mirrored, 1);
  EXPECT_GT(MaxAbsDiff(mirrored, filmed.frequency), 1.0);
  // ...and the turned clip's maps are the clip's as filmed, not their mirror image.
  EXPECT_LT(MaxAbsDiff(turned.frequency, filmed.frequency), 1e-4);
  EXPECT_LT(MaxAbsDiff(turned.power, filmed.power), 1e-3 * cv::norm(filmed.power, cv::NORM_INF));
}

TEST_F(PredictorTest, AClipTheJudgeCannotTellKeepsTheWayLastTold) {
  // A judge whose score is the motion's lean to the right (one hidden unit, linear where it is
  // used: a ramp over the map's columns and a large bias): the lopsided clip moves more on its
  // right, so it flies right and its mirror image left; a still clip scores 0 and tells nothing.
  Eigen::MatrixXf ramp(1, kMotionMapGrid * kMotionMapGrid);
  for (int y = 0; y < kMotionMapGrid; ++y)
    for (int x = 0; x < kMotionMapGrid; ++x) ramp(0, y * kMotionMapGrid + x) = x - 7.5f;
  FlyJudge judge(ramp, Eigen::VectorXf::Constant(1, 1000), Eigen::VectorXf::Ones(1), 0);
  judge.set_margin(1.0);
  judge.Save(dir_ / kFlyJudgeFile);
  Predictor predictor(dir_ / "model.pt", 1, "cpu");
  ASSERT_NE(predictor.fly_judge(), nullptr);
  predictor.set_flag_flies(FlagFlies::kAuto);
  const std::vector<cv::Mat> right = LopsidedClip();
  std::vector<cv::Mat> left;
  for (const cv::Mat& f : right) {
    cv::Mat m;
    cv::flip(f, m, 1);
    left.push_back(m);
  }
  const std::vector<cv::Mat> still(30, cv::Mat(32, 32, CV_8UC1, cv::Scalar(120)));
  // Nothing told yet: as filmed.
  Prediction p = predictor.PredictFrames(still);
  EXPECT_TRUE(p.undecided);
  EXPECT_FALSE(p.turned);
  p = predictor.PredictFrames(left);
  EXPECT_FALSE(p.undecided);
  EXPECT_TRUE(p.turned);
  // The calm clip keeps the left-flying flag's way (it used to be read as filmed: a coin's throw
  // for a judge, 3.4 m/s of error for a limp flag read the wrong way round).
  p = predictor.PredictFrames(still);
  EXPECT_TRUE(p.undecided);
  EXPECT_TRUE(p.turned);
  EXPECT_FALSE(predictor.PredictFrames(right).turned);
  p = predictor.PredictFrames(still);
  EXPECT_TRUE(p.undecided);
  EXPECT_FALSE(p.turned);
  // A clip without a scene tells the way no more than a still one: sensor noise stronger on the
  // right (a covered lens) is judged "right", and a later calm clip kept that noise's way.
  p = predictor.PredictFrames(left);
  ASSERT_TRUE(p.turned);
  std::vector<cv::Mat> noise;
  cv::RNG rng(8);
  for (int t = 0; t < 30; ++t) {
    cv::Mat f(32, 32, CV_8UC1);
    for (int y = 0; y < 32; ++y)
      for (int x = 0; x < 32; ++x) f.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(6 + rng.gaussian(0.15 * x));
    noise.push_back(f);
  }
  p = predictor.PredictFrames(noise);
  ASSERT_TRUE(p.no_scene) << p.contrast;
  ASSERT_FALSE(p.undecided) << "the judge must decide the noise clip for this test";
  ASSERT_FALSE(p.turned) << "the noise must lean right for this test";
  p = predictor.PredictFrames(still);
  EXPECT_TRUE(p.undecided);
  EXPECT_TRUE(p.turned) << "the noise clip's way replaced the left-flying flag's";
}

TEST_F(PredictorTest, MapsComeForEveryKindOfSdn) {
  // The maps are the strongest peak's power and frequency whatever else the model reads: a model
  // with far phase steps or the mode shape estimates with maps asked for as without (the far
  // steps once made the maps' options invalid, and every estimate failed while rviz watched).
  const std::vector<cv::Mat> clip = LopsidedClip();
  for (const char* variant : {"far", "mode_shape"}) {
    SCOPED_TRACE(variant);
    ModelConfig c;
    c.arch = "sdn";
    c.k = 3;
    c.width = 8;
    c.input_size = 32;
    if (std::string(variant) == "far") {
      c.phase_steps = true;
      c.phase_step_far = 4;
    } else {
      c.mode_shape = true;
    }
    WindNet net(c);
    const fs::path path = dir_ / (std::string(variant) + ".pt");
    SaveWindNet(net, path);
    Predictor predictor(path, 1, "cpu");
    PeakMaps maps;
    const Prediction with = predictor.PredictFrames(clip, &maps);
    const Prediction without = predictor.PredictFrames(clip);
    EXPECT_EQ(with.speed, without.speed);
    ASSERT_EQ(maps.frequency.size(), cv::Size(32, 32));
    ASSERT_EQ(maps.power.size(), cv::Size(32, 32));
    // The stripes' frequency grows from left to right (1 Hz + 0.25 Hz per pixel).
    EXPECT_LT(maps.frequency.at<float>(16, 2), maps.frequency.at<float>(16, 20));
  }
}

}  // namespace
}  // namespace clothwind::learn
