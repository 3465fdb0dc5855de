// The fly-direction cues on clips whose answer is known by construction: a wave travelling along
// a flag that is held at one end, each cue alone (a travelling wave of even amplitude, a standing
// sway that grows toward one end), exact sign reversal under mirroring, a still clip, refusals.
#include "learn/fly_direction.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
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

// A level camera with the given heading: optical axis along it, picture's right 90 deg clockwise
// of it, picture's down along -z (REP 103 optical axes as the columns).
Eigen::Matrix3d LevelCamera(double heading) {
  Eigen::Matrix3d axes;
  axes.col(0) = Eigen::Vector3d(std::sin(heading), -std::cos(heading), 0);
  axes.col(2) = Eigen::Vector3d(std::cos(heading), std::sin(heading), 0);
  axes.col(1) = axes.col(2).cross(axes.col(0));
  return axes;
}

// The angle between two headings [rad], 0 .. pi.
double HeadingGap(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

TEST(EquivalentCameraHeading, ALevelCameraHasItsOwnHeadingAndTheSameWaysAsTheParameter) {
  for (const double heading : {0.0, 0.4, M_PI / 2, 2.5, M_PI, -1.0, -M_PI / 2}) {
    const auto got = EquivalentCameraHeading(LevelCamera(heading));
    ASSERT_TRUE(got) << heading;
    EXPECT_NEAR(HeadingGap(*got, heading), 0, 1e-12) << heading;
    EXPECT_LE(std::abs(*got), M_PI + 1e-12);
    for (const double wind : {0.1, 1.3, 2.9, -2.2}) {
      EXPECT_EQ(FlyDirectionFromWind(wind, *got, 0.2), FlyDirectionFromWind(wind, heading, 0.2)) << heading << " " << wind;
    }
  }
}

TEST(EquivalentCameraHeading, PitchKeepsTheHeadingAndUpsideDownReversesTheWay) {
  const double north = M_PI / 2;
  const Eigen::Matrix3d level = LevelCamera(north);
  // Pitched up 35 deg or down 20 deg (about the picture's right), rolled 30 deg (about the axis).
  for (const Eigen::Matrix3d& camera :
       {Eigen::Matrix3d(level * Eigen::AngleAxisd(0.61, Eigen::Vector3d::UnitX())),
        Eigen::Matrix3d(level * Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitX())),
        Eigen::Matrix3d(level * Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()))}) {
    const auto got = EquivalentCameraHeading(camera);
    ASSERT_TRUE(got);
    EXPECT_NEAR(HeadingGap(*got, north), 0, 1e-9);
  }
  // Upside down (rolled 180 deg): the air moving east, to a level camera's right, crosses this
  // camera's picture to its left.
  const auto upside_down = EquivalentCameraHeading(level * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  ASSERT_TRUE(upside_down);
  EXPECT_NEAR(HeadingGap(*upside_down, -north), 0, 1e-9);
  EXPECT_EQ(FlyDirectionFromWind(0.0, north, 0.2), FlyDirection::kRight);
  EXPECT_EQ(FlyDirectionFromWind(0.0, *upside_down, 0.2), FlyDirection::kLeft);
  // Looking straight down with the picture's right to the east: as a level camera facing north.
  Eigen::Matrix3d down;
  down.col(0) = Eigen::Vector3d(1, 0, 0);
  down.col(2) = Eigen::Vector3d(0, 0, -1);
  down.col(1) = down.col(2).cross(down.col(0));
  ASSERT_TRUE(EquivalentCameraHeading(down));
  EXPECT_NEAR(HeadingGap(*EquivalentCameraHeading(down), north), 0, 1e-12);
}

TEST(EquivalentCameraHeading, ACameraOnItsSideOrANonFiniteRotationHasNone) {
  const Eigen::Matrix3d level = LevelCamera(1.0);
  EXPECT_TRUE(EquivalentCameraHeading(level * Eigen::AngleAxisd(0.75, Eigen::Vector3d::UnitZ())));   // 43 deg
  EXPECT_FALSE(EquivalentCameraHeading(level * Eigen::AngleAxisd(0.82, Eigen::Vector3d::UnitZ())));  // 47 deg
  EXPECT_FALSE(EquivalentCameraHeading(level * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())));
  Eigen::Matrix3d bad = level;
  bad(0, 0) = std::nan("");
  EXPECT_FALSE(EquivalentCameraHeading(bad));
}

TEST(EquivalentCameraHeading, ReadsAStaticTransformPublishersYawPitchRoll) {
  // static_transform_publisher's `x y z yaw pitch roll` is the rotation Rz(yaw) Ry(pitch) Rx(roll):
  // `0 0 0 0 0 -1.5707963` puts the optical axis along +y and the picture's right along +x, a
  // level camera facing +y.
  const Eigen::Matrix3d camera = (Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(-1.5707963, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
  EXPECT_NEAR((camera.col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 0, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(camera));
  EXPECT_NEAR(*EquivalentCameraHeading(camera), M_PI / 2, 1e-6);
  // docs/sdn.md's example, `3 0 0 -1.5707963 0 -1.5707963 anemometer ...`: a level camera facing the
  // instrument's north mark (+x), its picture's right along -y: heading 0.
  const Eigen::Matrix3d example = (Eigen::AngleAxisd(-1.5707963, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(-1.5707963, Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
  EXPECT_NEAR((example.col(2) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR((example.col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(example));
  EXPECT_NEAR(*EquivalentCameraHeading(example), 0, 1e-6);
  // Its camera (`... 2.6179939 0 1.5707963 ...`): facing 60 deg, upside down, its picture's right
  // toward 150 deg as a level camera facing -120 deg sees it. The inverse transform (frames
  // swapped in the lookup) reads -90 deg, so a wind toward 60 deg is end-on only read right.
  const Eigen::Matrix3d upside_down = (Eigen::AngleAxisd(2.6179939, Eigen::Vector3d::UnitZ()) *
                                       Eigen::AngleAxisd(1.5707963, Eigen::Vector3d::UnitX()))
                                          .toRotationMatrix();
  EXPECT_NEAR((upside_down.col(2) - Eigen::Vector3d(std::cos(M_PI / 3), std::sin(M_PI / 3), 0)).norm(), 0, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(upside_down));
  EXPECT_NEAR(*EquivalentCameraHeading(upside_down), -2 * M_PI / 3, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(upside_down.transpose()));
  EXPECT_NEAR(*EquivalentCameraHeading(upside_down.transpose()), -M_PI / 2, 1e-6);
  EXPECT_EQ(FlyDirectionFromWind(M_PI / 3, *EquivalentCameraHeading(upside_down), 0.35), std::nullopt);
  EXPECT_EQ(FlyDirectionFromWind(0.0, *EquivalentCameraHeading(upside_down), 0.35), FlyDirection::kLeft);
}

}  // namespace
}  // namespace clothwind::learn
