#include "sensors/clip_preprocess.h"

#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace clothwind::sensors {
namespace {

TEST(ClipPreprocessTest, DefaultRoiIsCentredSquare) {
  const SquareRoi r = ResolveRoi({}, 320, 240);
  EXPECT_EQ(r.x, 40);
  EXPECT_EQ(r.y, 0);
  EXPECT_EQ(r.size, 240);
  const SquareRoi p = ResolveRoi({}, 240, 320);
  EXPECT_EQ(p.x, 0);
  EXPECT_EQ(p.y, 40);
}

TEST(ClipPreprocessTest, RoiOutsideImageIsAnError) {
  EXPECT_NO_THROW(ResolveRoi({20, 10, 230}, 320, 240));
  // One edge at a time (a case past two edges passed with either check gone), and the exact fits.
  EXPECT_THROW(ResolveRoi({100, 0, 230}, 320, 240), std::invalid_argument);  // right edge only
  EXPECT_THROW(ResolveRoi({0, 20, 230}, 320, 240), std::invalid_argument);   // bottom edge only
  EXPECT_THROW(ResolveRoi({-1, 0, 10}, 320, 240), std::invalid_argument);
  EXPECT_THROW(ResolveRoi({0, -1, 10}, 320, 240), std::invalid_argument);
  EXPECT_NO_THROW(ResolveRoi({80, 0, 240}, 320, 240));   // touching the right edge
  EXPECT_NO_THROW(ResolveRoi({0, 10, 230}, 320, 240));   // touching the bottom edge
}

TEST(ClipPreprocessTest, CropsGreysAndResizes) {
  // A bgr image: pure blue left of column 100, pure red from column 100; the roi covers only red
  // in its right half, so the output's left half is the luma of blue and its right half of red.
  cv::Mat image(240, 320, CV_8UC3, cv::Scalar(255, 0, 0));
  image(cv::Rect(100, 0, 220, 240)).setTo(cv::Scalar(0, 0, 255));
  // And a green band across rows 110-129, which the roi (rows 20-119) ends in: output rows 45-49.
  // Read there, the roi's y counts (columns alone passed with y ignored, or x and y swapped).
  image(cv::Rect(0, 110, 320, 20)).setTo(cv::Scalar(0, 255, 0));
  const cv::Mat out = PreprocessClipFrame(image, ClipSourceEncoding::kBgr8, {50, 20, 100}, 50);
  ASSERT_EQ(out.type(), CV_8UC1);
  ASSERT_EQ(out.rows, 50);
  ASSERT_EQ(out.cols, 50);
  // BT.601 luma: blue 0.114 * 255 = 29, red 0.299 * 255 = 76, green 0.587 * 255 = 150.
  EXPECT_NEAR(out.at<uint8_t>(25, 10), 29, 1);
  EXPECT_NEAR(out.at<uint8_t>(25, 40), 76, 1);
  EXPECT_NEAR(out.at<uint8_t>(47, 10), 150, 1);
  EXPECT_NEAR(out.at<uint8_t>(47, 40), 150, 1);
  EXPECT_NEAR(out.at<uint8_t>(43, 10), 29, 1);  // above the band
  // rgb8 of the same bytes reads red and blue swapped.
  const cv::Mat swapped = PreprocessClipFrame(image, ClipSourceEncoding::kRgb8, {50, 20, 100}, 50);
  EXPECT_NEAR(swapped.at<uint8_t>(25, 10), 76, 1);
  EXPECT_NEAR(swapped.at<uint8_t>(25, 40), 29, 1);
}

TEST(ClipPreprocessTest, ColourFramesKeepTheColourAndTheirGreyIsTheGreyFrame) {
  // Red against green of nearly one grey (76 and 75): the grey frame hides the edge, the colour
  // frame keeps it, and the colour frame's grey is the grey frame (up to resize rounding).
  cv::Mat image(240, 320, CV_8UC3, cv::Scalar(0, 128, 0));
  image(cv::Rect(100, 0, 220, 240)).setTo(cv::Scalar(0, 0, 255));
  const cv::Mat grey = PreprocessClipFrame(image, ClipSourceEncoding::kBgr8, {50, 20, 100}, 50);
  const cv::Mat colour = PreprocessClipFrame(image, ClipSourceEncoding::kBgr8, {50, 20, 100}, 50, true);
  ASSERT_EQ(colour.type(), ClipFrameCvType(true));
  ASSERT_EQ(colour.size(), grey.size());
  EXPECT_EQ(colour.at<cv::Vec3b>(25, 10), cv::Vec3b(0, 128, 0));
  EXPECT_EQ(colour.at<cv::Vec3b>(25, 40), cv::Vec3b(0, 0, 255));
  EXPECT_LE(std::abs(grey.at<uint8_t>(25, 10) - grey.at<uint8_t>(25, 40)), 2);
  cv::Mat grey_of_colour;
  cv::cvtColor(colour, grey_of_colour, cv::COLOR_BGR2GRAY);
  EXPECT_LE(cv::norm(grey_of_colour, grey, cv::NORM_INF), 1.0);
  // rgb8 bytes are reordered to BGR; a grey source is repeated in all three channels.
  const cv::Mat from_rgb = PreprocessClipFrame(image, ClipSourceEncoding::kRgb8, {50, 20, 100}, 50, true);
  EXPECT_EQ(from_rgb.at<cv::Vec3b>(25, 40), cv::Vec3b(255, 0, 0));
  cv::Mat mono(240, 320, CV_8UC1);
  cv::randu(mono, 0, 256);
  const cv::Mat mono_grey = PreprocessClipFrame(mono, ClipSourceEncoding::kMono8, {}, 60);
  const cv::Mat mono_colour = PreprocessClipFrame(mono, ClipSourceEncoding::kMono8, {}, 60, true);
  std::vector<cv::Mat> planes;
  cv::split(mono_colour, planes);
  ASSERT_EQ(planes.size(), 3u);
  for (const cv::Mat& plane : planes) EXPECT_EQ(cv::norm(plane, mono_grey, cv::NORM_INF), 0.0);
  EXPECT_STREQ(ClipFrameEncoding(true), "bgr8");
  EXPECT_STREQ(ClipFrameEncoding(false), "mono8");
}

TEST(ClipPreprocessTest, AreaResizeAveragesFineTexture) {
  // A 1-pixel checkerboard 0/200 shrunk 4x must average to ~100 everywhere (no aliasing).
  cv::Mat image(400, 400, CV_8UC1);
  for (int r = 0; r < 400; ++r)
    for (int c = 0; c < 400; ++c) image.at<uint8_t>(r, c) = ((r + c) % 2) ? 200 : 0;
  const cv::Mat out = PreprocessClipFrame(image, ClipSourceEncoding::kMono8, {}, 100);
  double lo, hi;
  cv::minMaxLoc(out, &lo, &hi);
  EXPECT_GE(lo, 99);
  EXPECT_LE(hi, 101);
  // A 1-px checkerboard averages to ~100 under bilinear or bicubic shrinking too (any 2x2 block
  // does). One bright column in four does not: INTER_AREA averages the 4 source columns under an
  // output pixel (200 / 4 = 50 everywhere), while a point-sampling interpolation lands on or
  // between the stripes and gives 0, 200 or a stripe pattern (aliasing).
  cv::Mat stripes(400, 400, CV_8UC1, cv::Scalar(0));
  for (int c = 0; c < 400; c += 4) stripes.col(c).setTo(200);
  const cv::Mat shrunk = PreprocessClipFrame(stripes, ClipSourceEncoding::kMono8, {}, 100);
  ASSERT_EQ(shrunk.size(), cv::Size(100, 100));
  cv::minMaxLoc(shrunk, &lo, &hi);
  EXPECT_GE(lo, 49);
  EXPECT_LE(hi, 51);
}

TEST(ClipPreprocessTest, Mono16ScaledToEightBitsAndOutputIsACopy) {
  cv::Mat image(300, 300, CV_16UC1, cv::Scalar(256 * 123));
  const cv::Mat out = PreprocessClipFrame(image, ClipSourceEncoding::kMono16, {}, 300);
  EXPECT_EQ(out.at<uint8_t>(150, 150), 123);
  // 0xFF00 is 255 by the high byte (1/256) and 1/257 gives 254; 0x8000 is 128, and 1/255 gives
  // 129. (123's value could not tell the three apart.)
  const cv::Mat top = PreprocessClipFrame(cv::Mat(300, 300, CV_16UC1, cv::Scalar(0xFF00)), ClipSourceEncoding::kMono16, {}, 300);
  EXPECT_EQ(top.at<uint8_t>(150, 150), 255);
  const cv::Mat low = PreprocessClipFrame(cv::Mat(300, 300, CV_16UC1, cv::Scalar(0x8000)), ClipSourceEncoding::kMono16, {}, 300);
  EXPECT_EQ(low.at<uint8_t>(150, 150), 128);
  cv::Mat mono(300, 300, CV_8UC1, cv::Scalar(7));
  const cv::Mat copy = PreprocessClipFrame(mono, ClipSourceEncoding::kMono8, {}, 300);
  mono.setTo(9);
  EXPECT_EQ(copy.at<uint8_t>(0, 0), 7);
}

TEST(ClipPreprocessTest, EncodingsParseOrExplain) {
  EXPECT_EQ(ParseClipSourceEncoding("bgr8"), ClipSourceEncoding::kBgr8);
  EXPECT_EQ(ParseClipSourceEncoding("mono8"), ClipSourceEncoding::kMono8);
  try {
    ParseClipSourceEncoding("yuv422");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("yuv422"), std::string::npos);
  }
  cv::Mat wrong(10, 10, CV_8UC1);
  EXPECT_THROW(PreprocessClipFrame(wrong, ClipSourceEncoding::kBgr8, {}, 5), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sensors
