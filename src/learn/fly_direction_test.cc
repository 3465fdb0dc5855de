// The fly-direction cues on clips whose answer is known by construction: a wave travelling along
// a flag that is held at one end, each cue alone (a travelling wave of even amplitude, a standing
// sway that grows toward one end), exact sign reversal under mirroring, a still clip, refusals.
#include "learn/fly_direction.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "learn/test_mirrored_frames.h"

namespace clothwind::learn {
namespace {

constexpr int kFrames = 30;
constexpr int kCols = 48, kRows = 32;
// A temporal frequency on a DFT bin (3 cycles per clip), so the phase step is exactly -k.
constexpr double kOmega = 2 * M_PI * 3 / kFrames;

// A clip of kFrames kRows x kCols CV_8UC1 frames: grey 100 plus, at column x,
// amplitude(x) * sin(k x - omega t + phase) (k > 0: the pattern travels right).
template <typename Amplitude>
std::vector<cv::Mat> Clip(Amplitude amplitude, double k) {
  std::vector<cv::Mat> frames;
  for (int t = 0; t < kFrames; ++t) {
    cv::Mat f(kRows, kCols, CV_8UC1);
    for (int y = 0; y < kRows; ++y) {
      for (int x = 0; x < kCols; ++x) {
        const double v = 100 + amplitude(x) * std::sin(k * x - kOmega * t + 0.1 * y);
        f.at<uint8_t>(y, x) = cv::saturate_cast<uint8_t>(v);
      }
    }
    frames.push_back(f);
  }
  return frames;
}

// A flag on a pole at column 8, flying right to column 40: still at the hoist, its ripples
// growing toward the fly end and travelling there.
double FlagAmplitude(int x) { return x < 8 || x >= 40 ? 0.0 : 60.0 * (x - 8) / 32.0; }

TEST(FlyDirectionTest, AFlagHeldOnTheLeftFliesRightAndItsMirrorLeft) {
  const std::vector<cv::Mat> clip = Clip(FlagAmplitude, 0.4);
  const FlyDirectionCues right = EstimateFlyDirection(clip);
  EXPECT_LT(right.motion_skewness, -0.2);
  EXPECT_LT(right.phase_step, -0.2);
  EXPECT_GT(right.score, 0);
  EXPECT_EQ(right.direction, FlyDirection::kRight);

  const FlyDirectionCues left = EstimateFlyDirection(Mirrored(clip));
  EXPECT_EQ(left.direction, FlyDirection::kLeft);
  // Mirroring reverses each cue exactly: the decision cannot prefer one side.
  EXPECT_NEAR(left.motion_skewness, -right.motion_skewness, 1e-9);
  EXPECT_NEAR(left.phase_step, -right.phase_step, 1e-9);
  EXPECT_NEAR(left.score, -right.score, 1e-9);
  EXPECT_EQ(FlyDirectionName(left.direction), "left");
}

TEST(FlyDirectionTest, PhaseStepOfATravellingWaveIsMinusItsWavenumber) {
  // Even amplitude over columns 8..39: the motion is spread evenly (a box, no skew), only the
  // travel tells the way.
  for (const double k : {0.3, -0.5}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    const FlyDirectionCues c = EstimateFlyDirection(Clip([](int x) { return x < 8 || x >= 40 ? 0.0 : 50.0; }, k));
    EXPECT_NEAR(c.phase_step, -k, 0.02);  // 8-bit rounding is the only error
    EXPECT_NEAR(c.motion_skewness, 0.0, 0.05);
    EXPECT_EQ(c.direction, k > 0 ? FlyDirection::kRight : FlyDirection::kLeft);
  }
}

TEST(FlyDirectionTest, AStandingSwayGrowingRightFliesRightByItsSkewnessAlone) {
  // k = 0: every pixel in phase, nothing travels; the motion grows toward the right.
  const FlyDirectionCues c = EstimateFlyDirection(Clip(FlagAmplitude, 0.0));
  EXPECT_NEAR(c.phase_step, 0.0, 0.02);
  EXPECT_LT(c.motion_skewness, -0.2);
  EXPECT_EQ(c.direction, FlyDirection::kRight);
}

TEST(FlyDirectionTest, AStillClipScoresZeroAndStaysAsFilmed) {
  const FlyDirectionCues c = EstimateFlyDirection(Clip([](int) { return 0.0; }, 0.4));
  EXPECT_EQ(c.motion_skewness, 0.0);
  EXPECT_EQ(c.phase_step, 0.0);
  EXPECT_EQ(c.score, 0.0);
  EXPECT_EQ(c.direction, FlyDirection::kRight);
}

TEST(FlyDirectionTest, FloatFramesReadAsTheirBytes) {
  const std::vector<cv::Mat> clip = Clip(FlagAmplitude, 0.4);
  std::vector<cv::Mat> floats;
  for (const cv::Mat& f : clip) {
    cv::Mat g;
    f.convertTo(g, CV_32F);
    floats.push_back(g);
  }
  EXPECT_NEAR(EstimateFlyDirection(floats).score, EstimateFlyDirection(clip).score, 1e-9);
}

// The message of the std::invalid_argument that EstimateFlyDirection(frames) throws ("" if none).
std::string Refusal(const std::vector<cv::Mat>& frames) {
  try {
    EstimateFlyDirection(frames);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(FlyDirectionTest, RefusesTooFewFramesColourAndMixedSizesNamingTheFrame) {
  std::vector<cv::Mat> clip = Clip(FlagAmplitude, 0.4);
  EXPECT_NE(Refusal({clip[0], clip[1], clip[2]}).find("at least 4 frames, got 3"), std::string::npos);
  std::vector<cv::Mat> colour = clip;
  colour[5] = cv::Mat(kRows, kCols, CV_8UC3, cv::Scalar::all(0));
  EXPECT_NE(Refusal(colour).find("frame 5 is not single-channel"), std::string::npos);
  std::vector<cv::Mat> sizes = clip;
  sizes[7] = cv::Mat(kRows, kCols - 1, CV_8UC1, cv::Scalar::all(0));
  EXPECT_NE(Refusal(sizes).find("frame 7 is 47x32, expected 48x32"), std::string::npos);
  EXPECT_NE(Refusal(std::vector<cv::Mat>(4, cv::Mat(5, 2, CV_8UC1, cv::Scalar::all(0)))).find("at least 3 columns"),
            std::string::npos);
}

TEST(FlyDirectionTest, FlagFliesNamesRoundTripAndAStrangerIsRefusedByWhere) {
  for (const FlagFlies f : {FlagFlies::kRight, FlagFlies::kLeft, FlagFlies::kAuto}) {
    EXPECT_EQ(FlagFliesFromName(FlagFliesName(f), "--flag-flies"), f);
  }
  try {
    FlagFliesFromName("up", "~flag_flies");
    ADD_FAILURE() << "'up' was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "~flag_flies: expected right, left or auto, got 'up'");
  }
}

TEST(FlyDirectionTest, FromTheWindAFlagFliesTowardThePictureSideTheAirMovesTo) {
  // ENU: x east, y north. A camera looking north (heading 90 deg) has east on its right.
  const double north = M_PI / 2, end_on = 20 * M_PI / 180;
  EXPECT_EQ(FlyDirectionFromWind(0.0, north, end_on), FlyDirection::kRight);     // air moving east
  EXPECT_EQ(FlyDirectionFromWind(M_PI, north, end_on), FlyDirection::kLeft);     // west
  EXPECT_EQ(FlyDirectionFromWind(-M_PI / 4, north, end_on), FlyDirection::kRight);  // south-east, toward the camera
  EXPECT_EQ(FlyDirectionFromWind(3 * M_PI / 4, north, end_on), FlyDirection::kLeft);  // north-west, away
  // Along the optical axis, either way, and within end_on of it: end-on, no side.
  EXPECT_EQ(FlyDirectionFromWind(north, north, end_on), std::nullopt);
  EXPECT_EQ(FlyDirectionFromWind(-north, north, end_on), std::nullopt);
  EXPECT_EQ(FlyDirectionFromWind(north - 0.3, north, end_on), std::nullopt);
  EXPECT_EQ(FlyDirectionFromWind(north - 0.4, north, end_on), FlyDirection::kRight);
  // Turning camera and wind together changes nothing; angles wrap.
  for (const double turn : {0.7, -2.0, 2 * M_PI}) {
    EXPECT_EQ(FlyDirectionFromWind(0.3 + turn, north + turn, end_on), FlyDirection::kRight) << turn;
    EXPECT_EQ(FlyDirectionFromWind(M_PI - 0.3 + turn, north + turn, end_on), FlyDirection::kLeft) << turn;
  }
  // No reading (NaN) or no heading: nothing.
  EXPECT_EQ(FlyDirectionFromWind(std::nan(""), north, end_on), std::nullopt);
  EXPECT_EQ(FlyDirectionFromWind(0.0, std::nan(""), end_on), std::nullopt);
  // Nor with no end-on window (NaN compared false: every wind, even along the axis, had a side).
  EXPECT_EQ(FlyDirectionFromWind(north, north, std::nan("")), std::nullopt);
}

}  // namespace
}  // namespace clothwind::learn
