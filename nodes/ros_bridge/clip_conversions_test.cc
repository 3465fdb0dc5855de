#include "ros_bridge/clip_conversions.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>
#include <sensor_msgs/image_encodings.h>

namespace clothwind::ros_bridge {
namespace {

sensor_msgs::Image Uniform(const std::string& encoding, int bytes_per_pixel, std::vector<uint8_t> pixel) {
  sensor_msgs::Image msg;
  msg.width = 8;
  msg.height = 6;
  msg.encoding = encoding;
  msg.step = msg.width * bytes_per_pixel;
  for (uint32_t i = 0; i < msg.width * msg.height * bytes_per_pixel / pixel.size(); ++i)
    msg.data.insert(msg.data.end(), pixel.begin(), pixel.end());
  return msg;
}

TEST(ImageViewTest, TheCoreLayoutsAreViewedWithoutACopy) {
  const sensor_msgs::Image msg = Uniform("rgb8", 3, {10, 20, 30});
  cv::Mat view;
  sensors::ClipSourceEncoding encoding;
  ImageView(msg, &view, &encoding);
  EXPECT_EQ(encoding, sensors::ClipSourceEncoding::kRgb8);
  EXPECT_EQ(view.data, msg.data.data());
  EXPECT_EQ(view.at<cv::Vec3b>(5, 7), cv::Vec3b(10, 20, 30));
}

// A padded image (step past width x pixel size, as some drivers publish) is viewed row by row at
// its step: each row has its own value and the padding another (unpadded images hid a dropped
// step).
TEST(ImageViewTest, APaddedImageIsViewedAtItsStep) {
  sensor_msgs::Image msg;
  msg.width = 5;
  msg.height = 4;
  msg.encoding = "mono8";
  msg.step = 8;  // 3 bytes of padding a row
  msg.data.assign(msg.step * msg.height, 0xEE);
  for (uint32_t r = 0; r < msg.height; ++r)
    for (uint32_t c = 0; c < msg.width; ++c) msg.data[r * msg.step + c] = static_cast<uint8_t>(10 * r + c);
  cv::Mat view;
  sensors::ClipSourceEncoding encoding;
  ImageView(msg, &view, &encoding);
  ASSERT_EQ(view.rows, 4);
  ASSERT_EQ(view.cols, 5);
  for (int r = 0; r < view.rows; ++r)
    for (int c = 0; c < view.cols; ++c) EXPECT_EQ(view.at<uint8_t>(r, c), 10 * r + c) << r << "," << c;
}

TEST(ImageViewTest, CameraLayoutsTheCoreDoesNotReadAreConvertedToBgr) {
  cv::Mat view;
  sensors::ClipSourceEncoding encoding;
  // A UVC camera's YUV 4:2:2 (U Y V Y): mid grey, no colour.
  ImageView(Uniform("yuv422", 2, {128, 100, 128, 100}), &view, &encoding);
  EXPECT_EQ(encoding, sensors::ClipSourceEncoding::kBgr8);
  ASSERT_EQ(view.type(), CV_8UC3);
  ASSERT_EQ(view.size(), cv::Size(8, 6));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(view.at<cv::Vec3b>(3, 4)[c], 100, 2);
  // An industrial camera's Bayer mosaic (R G / G B) of one colour: R 200, G 100, B 50.
  sensor_msgs::Image bayer = Uniform("bayer_rggb8", 1, {0});
  for (uint32_t y = 0; y < bayer.height; ++y)
    for (uint32_t x = 0; x < bayer.width; ++x)
      bayer.data[y * bayer.step + x] = (y % 2 == 0 && x % 2 == 0) ? 200 : (y % 2 == 1 && x % 2 == 1) ? 50 : 100;
  ImageView(bayer, &view, &encoding);
  ASSERT_EQ(view.type(), CV_8UC3);
  const cv::Vec3b inner = view.at<cv::Vec3b>(3, 3);  // B G R
  EXPECT_NEAR(inner[0], 50, 2);
  EXPECT_NEAR(inner[1], 100, 2);
  EXPECT_NEAR(inner[2], 200, 2);
  // The copy outlives the message.
  const cv::Mat kept = view;
  bayer.data.assign(bayer.data.size(), 0);
  EXPECT_EQ(kept.at<cv::Vec3b>(3, 3), inner);
}

TEST(ImageViewTest, BigEndianMono16IsReadMostSignificantByteFirst) {
  // 0x1234 sent as 12 34 (cv_bridge refused it on the way to bgr8: every frame dropped).
  sensor_msgs::Image msg = Uniform("mono16", 2, {0x12, 0x34});
  msg.is_bigendian = 1;
  msg.data[2 * (3 * 8 + 5)] = 0xAB;  // pixel (row 3, column 5) = 0xAB34
  cv::Mat view;
  sensors::ClipSourceEncoding encoding;
  ImageView(msg, &view, &encoding);
  EXPECT_EQ(encoding, sensors::ClipSourceEncoding::kMono16);
  ASSERT_EQ(view.type(), CV_16UC1);
  EXPECT_EQ(view.at<uint16_t>(0, 0), 0x1234);
  EXPECT_EQ(view.at<uint16_t>(3, 5), 0xAB34);
  msg.encoding = "16UC1";  // mono16's other name
  ImageView(msg, &view, &encoding);
  EXPECT_EQ(view.at<uint16_t>(3, 5), 0xAB34);
  msg.encoding = "mono16";
  // The same bytes little-endian read the other way round, viewed in place.
  msg.is_bigendian = 0;
  ImageView(msg, &view, &encoding);
  EXPECT_EQ(view.at<uint16_t>(0, 0), 0x3412);
  EXPECT_EQ(view.data, msg.data.data());
}

TEST(ImageViewTest, BadImagesAreNamed) {
  cv::Mat view;
  sensors::ClipSourceEncoding encoding;
  auto what = [&](const sensor_msgs::Image& msg) -> std::string {
    try {
      ImageView(msg, &view, &encoding);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_NE(what(Uniform("mpeg4", 1, {0})).find("image encoding 'mpeg4' not supported"), std::string::npos);
  sensor_msgs::Image short_data = Uniform("mono8", 1, {7});
  short_data.data.resize(10);
  EXPECT_NE(what(short_data).find("image data has 10 bytes"), std::string::npos) << what(short_data);
  sensor_msgs::Image short_bayer = Uniform("bayer_rggb8", 1, {7});
  short_bayer.data.resize(10);
  EXPECT_NE(what(short_bayer).find("image data has 10 bytes"), std::string::npos) << what(short_bayer);
  // height x step wraps to 65536 in 32 bits, cv_bridge's arithmetic: it read 4 GB past the data.
  sensor_msgs::Image wrapped = Uniform("bayer_rggb8", 1, {7});
  wrapped.width = wrapped.step = 65536;
  wrapped.height = 65537;
  wrapped.data.assign(65536, 0);
  EXPECT_NE(what(wrapped).find("expected step * height = 4295032832"), std::string::npos) << what(wrapped);
  sensor_msgs::Image narrow = Uniform("yuv422", 2, {128, 60});
  narrow.step = narrow.width;  // 1 byte a pixel where yuv422 has 2
  EXPECT_NE(what(narrow).find("image step 8 < width * pixel size 16"), std::string::npos) << what(narrow);
  // YUV 4:2:2 holds two pixels in four bytes: OpenCV converts pairs, and an odd width with packed
  // rows read 2 bytes past the data (a SIGSEGV against a guard page).
  for (const std::string odd_encoding : {"yuv422", "yuv422_yuy2"}) {
    sensor_msgs::Image odd = Uniform(odd_encoding, 2, {128, 60});
    odd.width = 5;
    odd.height = 3;
    odd.step = 10;
    odd.data.resize(30);
    EXPECT_NE(what(odd).find("'" + odd_encoding + "' needs an even width (two pixels share their colour), got 5"),
              std::string::npos)
        << what(odd);
  }
  sensor_msgs::Image empty = Uniform("mono8", 1, {7});
  empty.width = 0;
  EXPECT_NE(what(empty).find("image is empty"), std::string::npos);
}

TEST(ToLabelReadingTest, SpeedsAWindMeasurementCannotHaveAreSkipped) {
  // -50 and 1e300 m/s were averaged into a minute of clip labels.
  clothwind::WindMeasurement m;
  m.header.stamp = ros::Time(1700000000.0);
  m.valid = true;
  for (double bad : {-50.0, 1e300}) {
    m.speed = bad;
    EXPECT_TRUE(std::isnan(ToLabelReading(m).speed)) << bad;
  }
  m.speed = 7.5;
  EXPECT_EQ(ToLabelReading(m).speed, 7.5);
  // The instrument travels with the reading, into the clip's label.json.
  m.source = "gill";
  m.header.frame_id = "mast_anemometer";
  m.relative = true;
  const sensors::LabelReading r = ToLabelReading(m);
  EXPECT_EQ(r.source, "gill");
  EXPECT_EQ(r.frame_id, "mast_anemometer");
  EXPECT_TRUE(r.relative);
  m.valid = false;
  EXPECT_TRUE(std::isnan(ToLabelReading(m).speed));
}

// Round trip of the layout: frame-major, row-major; stamps, crop and label carried, the label's
// direction with the frame it is in.
TEST(ToClipMsgTest, FramesStampsAndLabelAreCarriedWithTheDirectionsFrame) {
  sensors::LabelledClip c;
  for (int i = 0; i < 3; ++i) {
    sensors::ClipFrame f;
    f.stamp = 100.0 + 0.04 * i;
    f.image = cv::Mat(4, 5, CV_8UC1);
    for (int r = 0; r < 4; ++r)
      for (int col = 0; col < 5; ++col) f.image.at<uint8_t>(r, col) = static_cast<uint8_t>(100 * i + 10 * r + col);
    c.clip.frames.push_back(f);
  }
  // Every number distinct, so a field filled from its neighbour (x for y, mean for std, width
  // for height) is caught.
  c.clip.sequence = 7;
  c.roi = {10, 20, 300};
  c.source_width = 640;
  c.source_height = 480;
  c.frame_rate = 12.5;
  c.label.window = 45.0;  // not the default 60 s, which a constant would also give
  c.label.end = 100.08;
  c.label.mean = 4.5;
  c.label.std = 0.75;
  c.label.count = 12;
  c.label.direction_mean = -1.25;
  const clothwind::Clip msg = ToClipMsg(c, "camera_optical", "anemometer");
  EXPECT_EQ(msg.header.frame_id, "camera_optical");
  EXPECT_DOUBLE_EQ(msg.header.stamp.toSec(), 100.0);
  ASSERT_EQ(msg.frame_stamps.size(), 3u);
  EXPECT_NEAR(msg.frame_stamps[2].toSec(), 100.08, 1e-9);
  EXPECT_EQ(msg.width, 5u);
  EXPECT_EQ(msg.height, 4u);
  EXPECT_EQ(msg.encoding, "mono8");
  ASSERT_EQ(msg.data.size(), 3u * 4 * 5);
  EXPECT_EQ(msg.data[2 * 20 + 3 * 5 + 4], 200 + 30 + 4);  // frame 2, row 3, column 4
  EXPECT_EQ(msg.sequence, 7u);
  EXPECT_EQ(msg.num_frames, 3u);
  EXPECT_FLOAT_EQ(msg.frame_rate, 12.5f);
  EXPECT_EQ(msg.roi.x_offset, 10u);
  EXPECT_EQ(msg.roi.y_offset, 20u);
  EXPECT_EQ(msg.roi.width, 300u);
  EXPECT_EQ(msg.roi.height, 300u);
  EXPECT_FALSE(msg.roi.do_rectify);
  EXPECT_EQ(msg.source_width, 640u);
  EXPECT_EQ(msg.source_height, 480u);
  EXPECT_DOUBLE_EQ(msg.label_window, 45.0);
  EXPECT_DOUBLE_EQ(msg.wind_mean, 4.5);
  EXPECT_DOUBLE_EQ(msg.wind_std, 0.75);
  EXPECT_EQ(msg.wind_count, 12u);
  EXPECT_DOUBLE_EQ(msg.wind_direction_mean, -1.25);
  EXPECT_EQ(msg.wind_direction_frame_id, "anemometer");
}

}  // namespace
}  // namespace clothwind::ros_bridge
