#include "render/sensor_model.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/random.h"
#include "render/renderer.h"

namespace clothwind::render {
namespace {

// A smooth radiance image with some structure (gradients and a bright block).
cv::Mat TestRadiance(float shift = 0.0f) {
  cv::Mat m(64, 64, CV_32FC3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const bool block = x > 20 + shift && x < 40 + shift && y > 20 && y < 40;
      m.at<cv::Vec3f>(y, x) = block ? cv::Vec3f(1.2f, 1.0f, 0.8f)
                                    : cv::Vec3f(0.01f * x, 0.005f * (x + y), 0.3f);
    }
  return m;
}

TEST(SensorModel, AllOffIsExactlyDevelop) {
  const SensorModelParams off;
  const cv::Mat l = TestRadiance();
  EXPECT_EQ(cv::norm(ApplySensorModel({l}, off, 1), Develop(l), cv::NORM_INF), 0.0);
  // Blur off: the middle sub-frame is the frame.
  const cv::Mat a = TestRadiance(-4), b = TestRadiance(0), c = TestRadiance(4);
  EXPECT_EQ(cv::norm(ApplySensorModel({a, b, c}, off, 1), Develop(b), cv::NORM_INF), 0.0);
}

TEST(SensorModel, MotionBlurAveragesSubframes) {
  SensorModelParams s;
  s.motion_blur = true;
  const cv::Mat a = TestRadiance(-4), b = TestRadiance(0), c = TestRadiance(4);
  const cv::Mat blurred = ApplySensorModel({a, b, c}, s, 1);
  const cv::Mat mean = (a + b + c) / 3.0;
  EXPECT_LE(cv::norm(blurred, Develop(mean), cv::NORM_INF), 1.0);
  EXPECT_GT(cv::norm(blurred, Develop(b), cv::NORM_L1), 100.0);
}

TEST(SensorModel, NoiseIsZeroMeanOfTheExpectedSizeAndSeeded) {
  SensorModelParams s;
  s.noise = true;
  s.full_well = 1e9;   // read noise only: sigma known in display-linear units
  s.read_noise = 0.02;
  // A grey that develops to exactly 102 of 255, so rounding does not bias the comparison.
  const float display = SrgbToLinear(102.0f / 255.0f);
  const float radiance = InverseTone(display);
  cv::Mat flat(100, 100, CV_32FC3, cv::Scalar(radiance, radiance, radiance));
  const cv::Mat clean = Develop(flat);
  const cv::Mat noisy = ApplySensorModel({flat}, s, 3);
  cv::Mat diff;
  cv::Mat(noisy).convertTo(diff, CV_32F);
  cv::Mat cl;
  clean.convertTo(cl, CV_32F);
  diff -= cl;
  cv::Scalar mean, stddev;
  cv::meanStdDev(diff.reshape(1), mean, stddev);
  ASSERT_EQ(clean.at<cv::Vec3b>(0, 0)[0], 102);
  // Noise is added before sRGB encoding: its size in 8-bit levels is sigma times the slope of
  // the encoding there; the encoding's curvature biases the mean by slope' sigma^2 / 2.
  const double h = 1e-3;
  const double slope = (LinearToSrgb(display + h) - LinearToSrgb(display - h)) / (2 * h);
  const double curvature =
      (LinearToSrgb(display + h) - 2 * LinearToSrgb(display) + LinearToSrgb(display - h)) / (h * h);
  EXPECT_NEAR(mean[0], 0.5 * curvature * 0.02 * 0.02 * 255, 0.15);
  EXPECT_NEAR(stddev[0], 0.02 * slope * 255, 0.3);
  EXPECT_EQ(cv::norm(noisy, ApplySensorModel({flat}, s, 3), cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(noisy, ApplySensorModel({flat}, s, 4), cv::NORM_L1), 0.0);
}

// Shot noise: variance y / full_well grows with the signal (the test above sets full_well to 1e9,
// where it is nil, so dropping or mis-scaling the shot term passed it).
TEST(SensorModel, ShotNoiseGrowsWithTheSignal) {
  SensorModelParams s;
  s.noise = true;
  s.full_well = 300;  // sigma 0.035 at 0.37 of white, 0.058 at white
  s.read_noise = 0.0;
  double sigma[2], display[2];  // measured, display-linear
  const int levels[2] = {102, 170};
  for (int i = 0; i < 2; ++i) {
    display[i] = SrgbToLinear(levels[i] / 255.0f);
    const float radiance = InverseTone(static_cast<float>(display[i]));
    const cv::Mat flat(100, 100, CV_32FC3, cv::Scalar(radiance, radiance, radiance));
    const cv::Mat clean = Develop(flat);
    ASSERT_EQ(clean.at<cv::Vec3b>(0, 0)[0], levels[i]);
    cv::Mat noisy, cl;
    ApplySensorModel({flat}, s, 5).convertTo(noisy, CV_32F);
    clean.convertTo(cl, CV_32F);
    const cv::Mat diff = noisy - cl;
    cv::Scalar mean, stddev;
    cv::meanStdDev(diff.reshape(1), mean, stddev);
    // 8-bit levels back to display-linear units through the encoding's slope there.
    const double h = 1e-3;
    const double slope = (LinearToSrgb(display[i] + h) - LinearToSrgb(display[i] - h)) / (2 * h);
    sigma[i] = stddev[0] / (slope * 255);
    EXPECT_NEAR(sigma[i], std::sqrt(display[i] / s.full_well), 0.06 * sigma[i]) << levels[i];
  }
  // sqrt(y): the brighter grey is the noisier in display-linear units.
  EXPECT_NEAR(sigma[1] / sigma[0], std::sqrt(display[1] / display[0]), 0.1);
}

// Bounds that name their field: a huge subframes made the caller render that many meshes a
// frame, and a huge or non-finite read_noise made every pixel 0 or 255 (NaN before conversion).
TEST(SensorModel, OutOfRangeFieldsAreNamed) {
  const auto error = [](const nlohmann::json& j) {
    try {
      SensorModelParamsFromJson(j);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const nlohmann::json good = ToJson(SensorModelParams());
  nlohmann::json j = good;
  j["subframes"] = 100000;
  EXPECT_NE(error(j).find("field 'subframes' is 100000, expected in [1, 64]"), std::string::npos) << error(j);
  j["subframes"] = SensorModelParams::kMaxSubframes;
  EXPECT_EQ(error(j), "no error");
  j = good;
  j["read_noise"] = 1e300;
  EXPECT_NE(error(j).find("field 'read_noise' is 1e+300"), std::string::npos) << error(j);
  j = good;
  j["full_well"] = 1e-300;
  EXPECT_NE(error(j).find("field 'full_well'"), std::string::npos) << error(j);
  // Given in code, past the JSON reader, they are refused too.
  SensorModelParams s;
  s.noise = true;
  s.read_noise = std::numeric_limits<double>::quiet_NaN();
  try {
    ApplySensorModel({TestRadiance()}, s, 1);
    FAIL() << "a NaN read_noise was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("read_noise"), std::string::npos) << e.what();
  }
}

// Without blur an even count of sub-frames gives the later of the two middle ones (documented,
// kept: frames were made so).
TEST(SensorModel, EvenSubframeCountTakesTheLaterMiddleOne) {
  const SensorModelParams off;
  const cv::Mat a = TestRadiance(-6), b = TestRadiance(-2), c = TestRadiance(2), d = TestRadiance(6);
  EXPECT_EQ(cv::norm(ApplySensorModel({a, b, c, d}, off, 1), Develop(c), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(ApplySensorModel({a, b}, off, 1), Develop(b), cv::NORM_INF), 0.0);
}

TEST(SensorModel, JpegChangesBytesButKeepsTheImage) {
  SensorModelParams s;
  s.jpeg_quality = 60;
  const cv::Mat l = TestRadiance();
  const cv::Mat j = ApplySensorModel({l}, s, 1);
  const cv::Mat d = Develop(l);
  EXPECT_GT(cv::norm(j, d, cv::NORM_L1), 0.0);
  EXPECT_GT(cv::PSNR(j, d), 30.0);
}

TEST(SensorModel, JsonRoundTripAndErrors) {
  SensorModelParams s;
  s.motion_blur = true;
  s.subframes = 5;
  s.noise = true;
  s.full_well = 1234.5;
  s.read_noise = 0.01;
  s.jpeg_quality = 85;
  const nlohmann::json j = ToJson(s);
  EXPECT_EQ(ToJson(SensorModelParamsFromJson(nlohmann::json::parse(j.dump()))), j);
  nlohmann::json bad = j;
  bad["jpeg_quality"] = 101;
  EXPECT_THROW(SensorModelParamsFromJson(bad), std::invalid_argument);
  bad = j;
  bad.erase("noise");
  try {
    SensorModelParamsFromJson(bad);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("noise"), std::string::npos);
  }
}

TEST(FrameFiles, WrittenAtomicallyAndReadBackExactly) {
  const std::string dir = testing::TempDir() + "/render_frame_test_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const cv::Mat f = Develop(TestRadiance());
  WriteFrameAtomic(dir + "/f.png", f);
  const cv::Mat back = cv::imread(dir + "/f.png", cv::IMREAD_COLOR);
  EXPECT_EQ(cv::norm(back, f, cv::NORM_INF), 0.0);
  WriteFrameAtomic(dir + "/f.jpg", f, 90);
  EXPECT_EQ(cv::imread(dir + "/f.jpg").size(), f.size());
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 2);  // no temporary left behind
  EXPECT_THROW(WriteFrameAtomic(dir + "/f.tiff", f), std::runtime_error);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::render
