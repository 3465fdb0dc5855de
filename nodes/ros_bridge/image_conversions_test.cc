#include "ros_bridge/image_conversions.h"

#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::ros_bridge {
namespace {

sensor_msgs::CameraInfo Calibration(uint32_t width, uint32_t height) {
  sensor_msgs::CameraInfo c;
  c.width = width;
  c.height = height;
  c.distortion_model = "plumb_bob";
  c.D = {0.1, -0.2, 0.0, 0.0, 0.0};
  c.K = {500, 0, width / 2.0, 0, 500, height / 2.0, 0, 0, 1};
  c.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  c.P = {500, 0, width / 2.0, 0, 0, 500, height / 2.0, 0, 0, 0, 1, 0};
  return c;
}

sensor_msgs::Image Image(uint32_t width, uint32_t height) {
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(12.5);
  image.header.frame_id = "camera_optical_frame";
  image.width = width;
  image.height = height;
  return image;
}

TEST(CameraInfoForTest, AMatchingCalibrationIsPublishedWithTheImagesHeader) {
  std::string reason = "unset";
  const auto info = CameraInfoFor(Calibration(640, 480), Image(640, 480), &reason);
  EXPECT_EQ(reason, "");
  EXPECT_EQ(info->K[0], 500);
  EXPECT_EQ(info->D.size(), 5u);
  EXPECT_EQ(info->header.stamp, ros::Time(12.5));
  EXPECT_EQ(info->header.frame_id, "camera_optical_frame");
}

TEST(CameraInfoForTest, NoCalibrationGivesTheImageSizeOnlyAndNoReason) {
  std::string reason = "unset";
  const auto info = CameraInfoFor(sensor_msgs::CameraInfo(), Image(320, 240), &reason);
  EXPECT_EQ(reason, "");
  EXPECT_EQ(info->width, 320u);
  EXPECT_EQ(info->height, 240u);  // (the width alone passed a height left 0, or set from the width)
  EXPECT_EQ(info->K[0], 0);
}

TEST(CameraInfoForTest, ACalibrationForAnotherSizeIsLeftOutSayingWhy) {
  std::string reason;
  const auto info = CameraInfoFor(Calibration(640, 480), Image(320, 240), &reason);
  EXPECT_NE(reason.find("640x480"), std::string::npos) << reason;
  EXPECT_EQ(info->K[0], 0);
  EXPECT_EQ(info->width, 320u);
  EXPECT_EQ(info->height, 240u);
}

TEST(CameraInfoForTest, ACalibrationWithANonFiniteValueIsLeftOutNamingIt) {
  // set_camera_info is answered by camera_info_manager, which stores whatever it is sent.
  sensor_msgs::CameraInfo bad = Calibration(640, 480);
  bad.K[4] = std::numeric_limits<double>::quiet_NaN();
  std::string reason;
  auto info = CameraInfoFor(bad, Image(640, 480), &reason);
  EXPECT_NE(reason.find("K[4] is nan"), std::string::npos) << reason;
  EXPECT_EQ(info->K[0], 0);
  bad = Calibration(640, 480);
  bad.D[1] = std::numeric_limits<double>::infinity();
  info = CameraInfoFor(bad, Image(640, 480), &reason);
  EXPECT_NE(reason.find("D[1] is inf"), std::string::npos) << reason;
  EXPECT_TRUE(info->D.empty());
}

}  // namespace
}  // namespace clothwind::ros_bridge
