#include "sensors/pixel_format.h"

#include <linux/videodev2.h>

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/image_file.h"

namespace clothwind {
namespace sensors {
namespace {

TEST(PixelFormatTest, ParsesNamesAndRejectsUnknownOnes) {
  PixelFormat f = PixelFormat::kYuyv;
  std::string error;
  ASSERT_TRUE(ParsePixelFormat("mjpg", &f, &error));
  EXPECT_EQ(f, PixelFormat::kMjpeg);
  ASSERT_TRUE(ParsePixelFormat("GREY", &f, &error));
  EXPECT_EQ(f, PixelFormat::kGrey);
  ASSERT_TRUE(ParsePixelFormat("yuyv", &f, &error));
  EXPECT_EQ(f, PixelFormat::kYuyv);
  EXPECT_FALSE(ParsePixelFormat("NV12", &f, &error));
  EXPECT_NE(error.find("NV12"), std::string::npos);
  EXPECT_NE(error.find("YUYV, MJPEG, GREY"), std::string::npos);
  EXPECT_EQ(f, PixelFormat::kYuyv);  // untouched on failure
}

TEST(PixelFormatTest, FourccRoundTripsAndPrints) {
  for (PixelFormat f : {PixelFormat::kYuyv, PixelFormat::kMjpeg, PixelFormat::kGrey}) {
    PixelFormat back;
    ASSERT_TRUE(PixelFormatFromFourcc(PixelFormatFourcc(f), &back));
    EXPECT_EQ(back, f);
  }
  PixelFormat back;
  EXPECT_TRUE(PixelFormatFromFourcc(V4L2_PIX_FMT_JPEG, &back));
  EXPECT_EQ(back, PixelFormat::kMjpeg);
  EXPECT_FALSE(PixelFormatFromFourcc(V4L2_PIX_FMT_NV12, &back));
  EXPECT_EQ(FourccToString(V4L2_PIX_FMT_YUYV), "YUYV");
  EXPECT_EQ(FourccToString(V4L2_PIX_FMT_MJPEG), "MJPG");
  EXPECT_EQ(RosEncodingFor(PixelFormat::kGrey), "mono8");
  EXPECT_EQ(RosEncodingFor(PixelFormat::kMjpeg), "bgr8");
}

TEST(PixelFormatTest, GreyHonoursStrideAndCopiesPixels) {
  const int w = 5, h = 3, stride = 8;
  std::vector<uint8_t> buf(stride * h, 0xEE);  // padding bytes must not leak into the image
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) buf[r * stride + c] = static_cast<uint8_t>(10 * r + c);
  cv::Mat image;
  std::string error;
  ASSERT_TRUE(ConvertToImage(PixelFormat::kGrey, buf.data(), buf.size(), w, h, stride, &image,
                             &error))
      << error;
  ASSERT_EQ(image.type(), CV_8UC1);
  ASSERT_EQ(image.cols, w);
  ASSERT_EQ(image.rows, h);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) EXPECT_EQ(image.at<uint8_t>(r, c), 10 * r + c);
  buf[0] = 99;  // the image owns its pixels: the driver buffer is re-queued right away
  EXPECT_EQ(image.at<uint8_t>(0, 0), 0);
}

// Builds a YUYV buffer where every pixel has the same Y, U, V.
std::vector<uint8_t> UniformYuyv(int w, int h, int stride, uint8_t y, uint8_t u, uint8_t v) {
  std::vector<uint8_t> buf(stride * h, 0);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; c += 2) {
      uint8_t* p = &buf[r * stride + 2 * c];
      p[0] = y; p[1] = u; p[2] = y; p[3] = v;
    }
  return buf;
}

// A padded YUYV buffer (the driver's bytesperline past 2 x width) gives the image its unpadded
// twin gives: rows are read at the stride. Each row has its own Y and the padding is 0xEE, so a
// row read from the wrong offset shows (uniform rows hid a wrong step).
TEST(PixelFormatTest, YuyvRowsAreReadByTheDriversStride) {
  const int w = 4, h = 3;
  auto rows = [&](int stride) {
    std::vector<uint8_t> buf(stride * h, 0xEE);
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; c += 2) {
        uint8_t* p = &buf[r * stride + 2 * c];
        p[0] = p[2] = static_cast<uint8_t>(40 + 70 * r);
        p[1] = p[3] = 128;
      }
    return buf;
  };
  const auto padded = rows(12), tight = rows(8);
  cv::Mat from_padded, from_tight;
  std::string error;
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, padded.data(), padded.size(), w, h, 12, &from_padded, &error))
      << error;
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, tight.data(), tight.size(), w, h, 8, &from_tight, &error)) << error;
  EXPECT_EQ(cv::norm(from_padded, from_tight, cv::NORM_INF), 0.0);
  for (int r = 1; r < h; ++r)
    EXPECT_GT(from_padded.at<cv::Vec3b>(r, 0)[1], from_padded.at<cv::Vec3b>(r - 1, 0)[1] + 50) << r;
}

TEST(PixelFormatTest, YuyvConvertsWithBt601Colours) {
  const int w = 4, h = 2, stride = 12;  // 8 bytes of pixels + 4 of padding per row
  cv::Mat image;
  std::string error;
  // Neutral chroma: a grey level, equal channels, brighter Y gives brighter grey.
  auto dark = UniformYuyv(w, h, stride, 40, 128, 128);
  auto light = UniformYuyv(w, h, stride, 200, 128, 128);
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, dark.data(), dark.size(), w, h, stride, &image,
                             &error)) << error;
  ASSERT_EQ(image.type(), CV_8UC3);
  cv::Vec3b d = image.at<cv::Vec3b>(1, 3);
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, light.data(), light.size(), w, h, stride, &image,
                             &error)) << error;
  cv::Vec3b l = image.at<cv::Vec3b>(1, 3);
  EXPECT_EQ(d[0], d[1]);
  EXPECT_EQ(d[1], d[2]);
  EXPECT_EQ(l[0], l[2]);
  EXPECT_GT(l[1], d[1] + 100);
  // Strong V (Cr) is red: R (channel 2 in BGR) dominates; strong U (Cb) is blue.
  auto red = UniformYuyv(w, h, stride, 100, 128, 230);
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, red.data(), red.size(), w, h, stride, &image,
                             &error)) << error;
  cv::Vec3b r = image.at<cv::Vec3b>(0, 0);
  EXPECT_GT(r[2], r[1] + 60);
  EXPECT_GT(r[2], r[0] + 60);
  auto blue = UniformYuyv(w, h, stride, 100, 230, 128);
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, blue.data(), blue.size(), w, h, stride, &image,
                             &error)) << error;
  cv::Vec3b b = image.at<cv::Vec3b>(0, 0);
  EXPECT_GT(b[0], b[1] + 60);
  EXPECT_GT(b[0], b[2] + 60);
  // UVC cameras send BT.601 video range (Y 16..235): R = 1.164 (Y-16) + 1.596 (V-128),
  // G = 1.164 (Y-16) - 0.813 (V-128) - 0.391 (U-128), B = 1.164 (Y-16) + 2.018 (U-128).
  EXPECT_NEAR(r[0], 1.164 * 84, 1.0);                 // B = 97.8
  EXPECT_NEAR(r[1], 1.164 * 84 - 0.813 * 102, 1.0);   // G = 14.9
  EXPECT_EQ(r[2], 255);                               // R = 260.6, saturated
  auto black = UniformYuyv(w, h, stride, 16, 128, 128);
  auto white = UniformYuyv(w, h, stride, 235, 128, 128);
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, black.data(), black.size(), w, h, stride, &image,
                             &error)) << error;
  EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  ASSERT_TRUE(ConvertToImage(PixelFormat::kYuyv, white.data(), white.size(), w, h, stride, &image,
                             &error)) << error;
  EXPECT_EQ(image.at<cv::Vec3b>(1, 2), cv::Vec3b(255, 255, 255));
}

TEST(PixelFormatTest, YuyvRejectsShortBufferAndOddWidth) {
  cv::Mat image;
  std::string error;
  auto buf = UniformYuyv(4, 2, 8, 100, 128, 128);
  EXPECT_FALSE(ConvertToImage(PixelFormat::kYuyv, buf.data(), buf.size() - 1, 4, 2, 8, &image,
                              &error));
  EXPECT_NE(error.find("needs 16"), std::string::npos) << error;
  EXPECT_FALSE(ConvertToImage(PixelFormat::kYuyv, buf.data(), buf.size(), 3, 2, 8, &image,
                              &error));
  EXPECT_NE(error.find("even width"), std::string::npos) << error;
}

TEST(PixelFormatTest, MjpegDecodesToBgrAndReportsGarbage) {
  cv::Mat original(48, 64, CV_8UC3);
  for (int r = 0; r < original.rows; ++r)
    for (int c = 0; c < original.cols; ++c)
      original.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uint8_t>(4 * c), 60,
                                               static_cast<uint8_t>(5 * r));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", original, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95}));
  cv::Mat image;
  std::string error;
  ASSERT_TRUE(ConvertToImage(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 64, 48, 0, &image,
                             &error)) << error;
  ASSERT_EQ(image.type(), CV_8UC3);
  EXPECT_LT(cv::norm(image, original, cv::NORM_L1) / original.total() / 3, 3.0);
  // The negotiated size must match what the JPEG says.
  EXPECT_FALSE(ConvertToImage(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 640, 480, 0, &image,
                              &error));
  EXPECT_NE(error.find("64x48"), std::string::npos) << error;
  std::vector<uint8_t> garbage(500, 0x5a);
  EXPECT_FALSE(ConvertToImage(PixelFormat::kMjpeg, garbage.data(), garbage.size(), 64, 48, 0,
                              &image, &error));
  EXPECT_NE(error.find("start-of-image"), std::string::npos) << error;
  // A JPEG cut short decodes (libjpeg greys the missing rows and only warns): refused by its
  // missing end-of-image marker. Zeros after the marker (cameras pad their buffers) are fine.
  std::vector<uint8_t> cut(jpeg.begin(), jpeg.begin() + jpeg.size() * 2 / 3);
  EXPECT_FALSE(ConvertToImage(PixelFormat::kMjpeg, cut.data(), cut.size(), 64, 48, 0, &image, &error));
  EXPECT_NE(error.find("truncated"), std::string::npos) << error;
  std::vector<uint8_t> padded = jpeg;
  padded.resize(jpeg.size() + 300, 0x00);
  EXPECT_TRUE(ConvertToImage(PixelFormat::kMjpeg, padded.data(), padded.size(), 64, 48, 0, &image, &error))
      << error;
  // A start and an end marker around garbage: no scan, no image.
  std::vector<uint8_t> headed = {0xFF, 0xD8, 0x12, 0x34, 0x56, 0xFF, 0xD9};
  EXPECT_FALSE(ConvertToImage(PixelFormat::kMjpeg, headed.data(), headed.size(), 64, 48, 0, &image, &error));
  EXPECT_NE(error.find("no start-of-scan marker"), std::string::npos) << error;
  // With a scan marker, garbage still fails in the decoder.
  std::vector<uint8_t> scanned = {0xFF, 0xD8, 0xFF, 0xDA, 0x12, 0x34, 0x56, 0xFF, 0xD9};
  EXPECT_FALSE(ConvertToImage(PixelFormat::kMjpeg, scanned.data(), scanned.size(), 64, 48, 0, &image, &error));
  EXPECT_NE(error.find("MJPEG decode failed"), std::string::npos) << error;
}

TEST(PixelFormatTest, AnMjpegFrameDamagedInsideIntactMarkersIsRefused) {
  // A transfer corrupted, not lost: bytes inside the entropy-coded data changed, both markers
  // intact. libjpeg decodes it into made-up blocks and only warns; cv::imdecode returned that
  // image, and the camera published it. Every damage that libjpeg notices must be refused, the
  // undamaged frame still decoded (grey frames come out BGR too).
  cv::Mat original(96, 128, CV_8UC3);
  cv::randu(original, 0, 255);
  cv::GaussianBlur(original, original, cv::Size(5, 5), 2.0);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", original, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
  size_t scan = 0;
  for (size_t i = 2; i + 1 < jpeg.size(); ++i)
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xDA) scan = i;
  ASSERT_GT(scan, 0u);
  cv::Mat image;
  std::string error;
  int refused = 0, noticed = 0;
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<uint8_t> damaged = jpeg;
    // Ten bytes overwritten a third of the way into the scan data, never with a marker byte.
    const size_t at = scan + 20 + (damaged.size() - scan - 40) / 3 + static_cast<size_t>(trial) * 7;
    for (size_t k = 0; k < 10; ++k) damaged[at + k] = static_cast<uint8_t>((37 * (trial + k) + 11) % 255);
    // What libjpeg says of it (the check image_file.h makes of files). Here every complaint is of
    // damage: a bad code, or the rest of the scan (tens of bytes) left before the end marker.
    const std::string said = common::JpegDataProblem(damaged.data(), damaged.size());
    const bool damage = !said.empty();
    const bool ok = ConvertToImage(PixelFormat::kMjpeg, damaged.data(), damaged.size(), 128, 96, 0, &image, &error);
    noticed += damage;
    refused += !ok;
    if (damage) {
      EXPECT_FALSE(ok) << "trial " << trial << ": libjpeg said '" << said << "', yet the frame was published";
    }
    if (!ok) {
      EXPECT_NE(error.find("Corrupt JPEG data"), std::string::npos) << error;
    }
  }
  EXPECT_GT(noticed, 10) << "libjpeg noticed 22 of 40 when written";
  EXPECT_EQ(refused, noticed);
  ASSERT_TRUE(ConvertToImage(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 128, 96, 0, &image, &error)) << error;
  // What the Logitech C270 sends on every MJPEG frame: a few bytes before a restart marker.
  // libjpeg warns "3 extraneous bytes before marker 0xd0" and decodes the picture whole:
  // published as it is (refusing every such frame would lose the camera).
  std::vector<uint8_t> restarts;
  ASSERT_TRUE(cv::imencode(".jpg", original, restarts,
                           {cv::IMWRITE_JPEG_QUALITY, 90, cv::IMWRITE_JPEG_RST_INTERVAL, 4}));
  ASSERT_TRUE(ConvertToImage(PixelFormat::kMjpeg, restarts.data(), restarts.size(), 128, 96, 0, &image, &error))
      << error;
  const cv::Mat clean_restarts = image.clone();
  size_t rst = 0;
  for (size_t i = 2; i + 1 < restarts.size() && rst == 0; ++i)
    if (restarts[i] == 0xFF && restarts[i + 1] >= 0xD0 && restarts[i + 1] <= 0xD7) rst = i;
  ASSERT_GT(rst, 0u);
  restarts.insert(restarts.begin() + static_cast<std::ptrdiff_t>(rst), {0x00, 0x17, 0x2a});
  // The file check judges it as the live decoder does (it refused such frames saved to a folder).
  EXPECT_EQ(common::JpegDataProblem(restarts.data(), restarts.size()), "");
  ASSERT_TRUE(ConvertToImage(PixelFormat::kMjpeg, restarts.data(), restarts.size(), 128, 96, 0, &image, &error))
      << error;
  EXPECT_EQ(cv::norm(image, clean_restarts, cv::NORM_INF), 0.0);
  cv::Mat grey;
  cv::cvtColor(original, grey, cv::COLOR_BGR2GRAY);
  std::vector<uint8_t> grey_jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", grey, grey_jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
  ASSERT_TRUE(ConvertToImage(PixelFormat::kMjpeg, grey_jpeg.data(), grey_jpeg.size(), 128, 96, 0, &image, &error))
      << error;
  EXPECT_EQ(image.type(), CV_8UC3);
  std::vector<cv::Mat> channels;
  cv::split(image, channels);
  EXPECT_EQ(cv::norm(channels[0], channels[2], cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
