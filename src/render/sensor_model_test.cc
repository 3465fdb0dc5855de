#include "render/sensor_model.h"

#include <unistd.h>

#include <filesystem>
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
