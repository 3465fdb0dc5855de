#include "sensors/video_source.h"

#include <unistd.h>

#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/videoio.hpp>

#include "sensors/frame_timestamp_fake_clock.h"

namespace clothwind {
namespace sensors {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kMs = 1000000;

class VideoSourceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "clothwind_video_XXXXXX").string();
    ASSERT_NE(mkdtemp(tmpl.data()), nullptr) << tmpl;
    dir_ = tmpl;
    path_ = dir_ + "/clip.avi";
    // Motion-JPEG in AVI: OpenCV writes this without external codecs.
    cv::VideoWriter writer(path_, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 12.5,
                           cv::Size(64, 48));
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG/AVI here";
    for (int k = 0; k < 8; ++k) writer.write(cv::Mat(48, 64, CV_8UC3, cv::Scalar(20 * k, 100, 50)));
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string dir_, path_;
};

TEST_F(VideoSourceTest, PlaysAtTheFileRateToTheEnd) {
  FakeClock clock;
  VideoFileSource source(path_, 30.0, false, &clock);
  ASSERT_TRUE(source.Open()) << source.error();
  EXPECT_NEAR(source.NominalRate(), 12.5, 1e-6);
  int64_t previous = 0;
  for (int k = 0; k < 8; ++k) {
    Frame f;
    ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame) << k << " " << source.error();
    EXPECT_EQ(f.encoding, "bgr8");
    ASSERT_EQ(f.image.cols, 64);
    ASSERT_EQ(f.image.rows, 48);
    EXPECT_NEAR(f.image.at<cv::Vec3b>(24, 32)[0], 20 * k, 6);  // frame order survives
    EXPECT_EQ(f.sequence, static_cast<uint64_t>(k));  // (never read: every frame could say 0)
    if (k > 0) {
      EXPECT_EQ(f.stamp_ns - previous, 80 * kMs);
    }
    previous = f.stamp_ns;
  }
  Frame f;
  EXPECT_EQ(source.Read(&f, 1.0), ReadStatus::kEnd);
}

TEST_F(VideoSourceTest, LoopsWithIncreasingStamps) {
  FakeClock clock;
  VideoFileSource source(path_, 30.0, true, &clock);
  ASSERT_TRUE(source.Open()) << source.error();
  int64_t previous = 0;
  for (int k = 0; k < 20; ++k) {
    Frame f;
    ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame) << k << " " << source.error();
    EXPECT_NEAR(f.image.at<cv::Vec3b>(24, 32)[0], 20 * (k % 8), 6) << k;
    EXPECT_EQ(f.sequence, static_cast<uint64_t>(k)) << "the sequence runs on across loops";
    EXPECT_GT(f.stamp_ns, previous);
    previous = f.stamp_ns;
  }
  EXPECT_EQ(source.Status().at("loops"), "2");
}

// A file with no frame that decodes is an error either way it shows: OpenCV refusing to open it,
// or the first read finding nothing (it used to end like an empty recording, in silence).
TEST_F(VideoSourceTest, AVideoWithoutFramesIsAnErrorNotAnEnd) {
  const std::string empty = dir_ + "/empty.avi";
  {
    cv::VideoWriter writer(empty, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 12.5, cv::Size(64, 48));
    ASSERT_TRUE(writer.isOpened());
  }
  FakeClock clock;
  VideoFileSource source(empty, 30.0, true, &clock);
  if (!source.Open()) {
    EXPECT_NE(source.error().find(empty), std::string::npos) << source.error();
    return;
  }
  Frame f;
  EXPECT_EQ(source.Read(&f, 0.1), ReadStatus::kError);
  EXPECT_NE(source.error().find("no frame could be decoded"), std::string::npos) << source.error();
  EXPECT_FALSE(source.IsOpen());
}

TEST_F(VideoSourceTest, MissingFileIsAClearError) {
  FakeClock clock;
  VideoFileSource source(dir_ + "/nope.mp4", 30.0, false, &clock);
  EXPECT_FALSE(source.Open());
  EXPECT_NE(source.error().find("nope.mp4 does not exist"), std::string::npos) << source.error();
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
