#include "sensors/frame_source_folder.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "sensors/frame_timestamp_fake_clock.h"

namespace clothwind {
namespace sensors {
namespace {

namespace fs = std::filesystem;
constexpr int64_t kMs = 1000000;

class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "clothwind_folder_XXXXXX").string();
    path_ = mkdtemp(tmpl.data());
  }
  ~TempDir() { fs::remove_all(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// Writes frame_%04d.png, frame k a uniform image of value 10 k.
void WriteFrames(const std::string& dir, int n, int channels) {
  for (int k = 0; k < n; ++k) {
    cv::Mat m(24, 32, channels == 1 ? CV_8UC1 : CV_8UC3, cv::Scalar::all(10 * k));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", k);
    ASSERT_TRUE(cv::imwrite(dir + "/" + name, m));
  }
}

TEST(ImageFolderSourceTest, PlaysImagesInNameOrderAtTheRate) {
  TempDir dir;
  WriteFrames(dir.path(), 12, 1);
  std::ofstream(dir.path() + "/notes.txt") << "ignored";
  // A writer's hidden temporary (renamed into place when whole) is no frame either.
  fs::copy_file(dir.path() + "/frame_0005.png", dir.path() + "/.frame_0005.png");
  FakeClock clock;
  ImageFolderSource source(dir.path(), 25.0, false, &clock);
  ASSERT_TRUE(source.Open()) << source.error();
  EXPECT_EQ(source.files().size(), 12u);
  int64_t previous = 0;
  for (int k = 0; k < 12; ++k) {
    Frame f;
    ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame) << source.error();
    EXPECT_EQ(f.encoding, "mono8");
    EXPECT_EQ(f.image.at<uint8_t>(3, 3), 10 * k);  // frame_0010 after frame_0009
    EXPECT_EQ(f.sequence, static_cast<uint64_t>(k));
    if (k > 0) {
      EXPECT_EQ(f.stamp_ns - previous, 40 * kMs);
    }
    previous = f.stamp_ns;
  }
  Frame f;
  EXPECT_EQ(source.Read(&f, 1.0), ReadStatus::kEnd);
  EXPECT_DOUBLE_EQ(source.NominalRate(), 25.0);
}

TEST(ImageFolderSourceTest, LoopsWithIncreasingStamps) {
  TempDir dir;
  WriteFrames(dir.path(), 3, 3);
  FakeClock clock;
  ImageFolderSource source(dir.path(), 10.0, true, &clock);
  ASSERT_TRUE(source.Open());
  int64_t previous = 0;
  for (int k = 0; k < 7; ++k) {
    Frame f;
    ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame);
    EXPECT_EQ(f.encoding, "bgr8");
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_EQ(f.image.at<cv::Vec3b>(0, 0)[1], 10 * (k % 3));
    EXPECT_GT(f.stamp_ns, previous);
    previous = f.stamp_ns;
  }
}

TEST(ImageFolderSourceTest, ClearErrorsForMissingEmptyAndInconsistentFolders) {
  FakeClock clock;
  ImageFolderSource missing("/nonexistent/clothwind/frames", 10.0, false, &clock);
  EXPECT_FALSE(missing.Open());
  EXPECT_NE(missing.error().find("/nonexistent/clothwind/frames does not exist"), std::string::npos);

  TempDir empty;
  ImageFolderSource none(empty.path(), 10.0, false, &clock);
  EXPECT_FALSE(none.Open());
  EXPECT_NE(none.error().find("holds no images"), std::string::npos);

  TempDir mixed;
  WriteFrames(mixed.path(), 2, 1);
  ASSERT_TRUE(cv::imwrite(mixed.path() + "/frame_0002.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(0))));
  ImageFolderSource source(mixed.path(), 10.0, false, &clock);
  ASSERT_TRUE(source.Open());
  Frame f;
  ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame);
  ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame);
  // A bad frame, not a failed source: the recording goes on (camera_node counts the two apart).
  EXPECT_EQ(source.Read(&f, 1.0), ReadStatus::kBadFrame);
  EXPECT_TRUE(source.IsOpen());
  EXPECT_NE(source.error().find("frame_0002.png is 10x10 mono8, expected 32x24 mono8"),
            std::string::npos) << source.error();
  EXPECT_EQ(source.Read(&f, 1.0), ReadStatus::kEnd);

  // A header claiming more pixels than OpenCV allows makes imread throw: an error naming the
  // file, not an exception through the node (camera_node ended by std::terminate).
  TempDir bomb;
  WriteFrames(bomb.path(), 1, 1);
  std::ofstream(bomb.path() + "/frame_0001.pgm", std::ios::binary) << "P5\n100000 100000\n255\n";
  ImageFolderSource bombed(bomb.path(), 10.0, false, &clock);
  ASSERT_TRUE(bombed.Open());
  ASSERT_EQ(bombed.Read(&f, 1.0), ReadStatus::kFrame);
  EXPECT_EQ(bombed.Read(&f, 1.0), ReadStatus::kBadFrame);
  EXPECT_NE(bombed.error().find("cannot read image " + bomb.path() + "/frame_0001.pgm"), std::string::npos)
      << bombed.error();

  // A JPEG cut short (a recording cut by a power loss) decodes with grey rows where its data ends:
  // an error naming it, not a frame published as if seen.
  TempDir cut;
  cv::Mat noise(24, 32, CV_8UC1);
  cv::randu(noise, 0, 255);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", noise, jpeg));
  std::ofstream(cut.path() + "/frame_0000.jpg", std::ios::binary).write(reinterpret_cast<const char*>(jpeg.data()), jpeg.size());
  std::ofstream(cut.path() + "/frame_0001.jpg", std::ios::binary).write(reinterpret_cast<const char*>(jpeg.data()), jpeg.size() / 2);
  ImageFolderSource shortened(cut.path(), 10.0, false, &clock);
  ASSERT_TRUE(shortened.Open()) << shortened.error();
  ASSERT_EQ(shortened.Read(&f, 1.0), ReadStatus::kFrame);
  EXPECT_EQ(shortened.Read(&f, 1.0), ReadStatus::kBadFrame);
  EXPECT_NE(shortened.error().find("frame_0001.jpg (JPEG truncated"), std::string::npos) << shortened.error();
}

TEST(ImageFolderSourceTest, AnUnreadableImageKeepsItsSlotInTime) {
  // frame_0002 cannot be used (another size): the frames after it keep their own slots and
  // sequence numbers, as a camera's lost frame leaves a gap. Before, frame_0003 took frame_0002's
  // stamp: a clip across the bad frame held 31 intervals in 30 slots, every frequency 3 % high.
  TempDir dir;
  WriteFrames(dir.path(), 5, 1);
  ASSERT_TRUE(cv::imwrite(dir.path() + "/frame_0002.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(0))));
  FakeClock clock;
  ImageFolderSource source(dir.path(), 10.0, false, &clock);
  ASSERT_TRUE(source.Open()) << source.error();
  std::vector<ReadStatus> statuses;
  std::vector<int64_t> stamps, sequences, returned_at;
  for (int k = 0; k < 5; ++k) {
    Frame f;
    statuses.push_back(source.Read(&f, 1.0));
    returned_at.push_back(clock.MonotonicNs());
    if (statuses.back() != ReadStatus::kFrame) continue;
    if (stamps.empty()) stamps.push_back(f.stamp_ns);
    stamps.push_back(f.stamp_ns - stamps.front());
    sequences.push_back(static_cast<int64_t>(f.sequence));
  }
  stamps.erase(stamps.begin());
  EXPECT_EQ(statuses, (std::vector<ReadStatus>{ReadStatus::kFrame, ReadStatus::kFrame, ReadStatus::kBadFrame,
                                               ReadStatus::kFrame, ReadStatus::kFrame}));
  EXPECT_EQ(stamps, (std::vector<int64_t>{0, 100 * kMs, 300 * kMs, 400 * kMs}));
  EXPECT_EQ(sequences, (std::vector<int64_t>{0, 1, 3, 4}));
  // The bad frame is reported when its frame was due, not at once.
  EXPECT_EQ(returned_at[2] - returned_at[0], 200 * kMs);
  Frame f;
  EXPECT_EQ(source.Read(&f, 1.0), ReadStatus::kEnd);
}

TEST(ImageFolderSourceTest, ClosesItselfWhenNothingIsReadableAnyMore) {
  FakeClock clock;
  {
    TempDir dir;
    WriteFrames(dir.path(), 3, 1);
    ImageFolderSource source(dir.path(), 10.0, true, &clock);
    ASSERT_TRUE(source.Open());
    Frame f;
    ASSERT_EQ(source.Read(&f, 1.0), ReadStatus::kFrame);
    fs::remove_all(dir.path());
    // Bad frames until a whole round was unreadable; then the source has failed (kError).
    std::vector<ReadStatus> statuses;
    while (source.IsOpen() && statuses.size() < 10) statuses.push_back(source.Read(&f, 1.0));
    EXPECT_EQ(statuses, (std::vector<ReadStatus>{ReadStatus::kBadFrame, ReadStatus::kBadFrame, ReadStatus::kError}));
    EXPECT_FALSE(source.IsOpen());
    EXPECT_NE(source.error().find("no image readable any more"), std::string::npos) << source.error();
    EXPECT_FALSE(source.Open());
  }
}

TEST(ImageFolderSourceTest, OneBadImageInALoopedFolderNeverClosesIt) {
  // A good image between bad ones restarts the count of failures in a row: a looped folder of
  // three with one unreadable image read for ever (without the restart it closed after 3 bad reads).
  FakeClock clock;
  TempDir dir;
  WriteFrames(dir.path(), 3, 1);
  std::ofstream(dir.path() + "/frame_0001.png", std::ios::trunc) << "not a png";
  ImageFolderSource source(dir.path(), 10.0, true, &clock);
  ASSERT_TRUE(source.Open());
  int bad = 0;
  for (int k = 0; k < 12; ++k) {
    Frame f;
    const ReadStatus s = source.Read(&f, 1.0);
    ASSERT_NE(s, ReadStatus::kError) << k << " " << source.error();
    bad += s == ReadStatus::kBadFrame;
  }
  EXPECT_EQ(bad, 4);
  EXPECT_TRUE(source.IsOpen());
}

TEST(ImageFolderSourceTest, NormalizesSixteenBitAndAlpha) {
  cv::Mat image;
  std::string encoding;
  ASSERT_TRUE(NormalizeRecordedImage(cv::Mat(2, 2, CV_16UC1, cv::Scalar(65535)), &image, &encoding));
  EXPECT_EQ(encoding, "mono8");
  EXPECT_EQ(image.at<uint8_t>(0, 0), 255);
  // Scaled by 255/65535 (= 1/257), not saturated: a full-scale 65535 is 255 either way, but a
  // 16-bit PNG's mid grey 0x8080 must read 128 and a dark 1000 must read 4 (unscaled they
  // saturate to 255, a white frame), and bright channels stay apart from dark ones in colour.
  cv::Mat sixteen(1, 3, CV_16UC1);
  sixteen.at<uint16_t>(0, 0) = 0x8080;
  sixteen.at<uint16_t>(0, 1) = 1000;
  sixteen.at<uint16_t>(0, 2) = 0;
  ASSERT_TRUE(NormalizeRecordedImage(sixteen, &image, &encoding));
  EXPECT_EQ(encoding, "mono8");
  ASSERT_EQ(image.type(), CV_8UC1);
  EXPECT_EQ(image.at<uint8_t>(0, 0), 128);
  EXPECT_EQ(image.at<uint8_t>(0, 1), 4);
  EXPECT_EQ(image.at<uint8_t>(0, 2), 0);
  ASSERT_TRUE(NormalizeRecordedImage(cv::Mat(2, 2, CV_16UC3, cv::Scalar(257 * 10, 0x8080, 65535)), &image,
                                     &encoding));
  EXPECT_EQ(encoding, "bgr8");
  EXPECT_EQ(image.at<cv::Vec3b>(1, 0), cv::Vec3b(10, 128, 255));
  ASSERT_TRUE(NormalizeRecordedImage(cv::Mat(2, 2, CV_8UC4, cv::Scalar(1, 2, 3, 4)), &image, &encoding));
  EXPECT_EQ(encoding, "bgr8");
  EXPECT_EQ(image.at<cv::Vec3b>(1, 1), cv::Vec3b(1, 2, 3));
  EXPECT_FALSE(NormalizeRecordedImage(cv::Mat(2, 2, CV_8UC2), &image, &encoding));
}

}  // namespace
}  // namespace sensors
}  // namespace clothwind
