#include "common/image_file.h"

#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace clothwind::common {
namespace {
namespace fs = std::filesystem;

class ImageFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_image_file_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    image_ = cv::Mat(48, 64, CV_8UC3);
    cv::randu(image_, 0, 255);
    cv::imencode(".jpg", image_, jpeg_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path Write(const std::string& name, const std::vector<uint8_t>& bytes) {
    std::ofstream(dir_ / name, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
    return dir_ / name;
  }
  fs::path dir_;
  cv::Mat image_;
  std::vector<uint8_t> jpeg_;
};

TEST_F(ImageFileTest, AWholeJpegReadsAsImreadReadsIt) {
  const fs::path p = Write("whole.jpg", jpeg_);
  for (const int flags : {cv::IMREAD_COLOR, cv::IMREAD_GRAYSCALE, cv::IMREAD_UNCHANGED}) {
    std::string why;
    const cv::Mat read = ReadImageFile(p, flags, &why);
    const cv::Mat expected = cv::imread(p.string(), flags);
    ASSERT_FALSE(read.empty()) << why;
    EXPECT_EQ(read.type(), expected.type());
    EXPECT_EQ(cv::norm(read, expected, cv::NORM_INF), 0.0);
  }
}

TEST_F(ImageFileTest, AJpegDamagedInItsMiddleIsRefusedWhereImreadMakesBlocksUp) {
  // 40 bytes overwritten in the middle of the scan: both markers stay, libjpeg decodes made-up
  // blocks and only prints "Corrupt JPEG data" (naming no file).
  std::vector<uint8_t> damaged = jpeg_;
  size_t scan = 0;
  for (size_t i = 2; i + 1 < damaged.size(); ++i)
    if (damaged[i] == 0xFF && damaged[i + 1] == 0xDA) scan = i;
  ASSERT_GT(scan, 0u);
  const size_t middle = (scan + damaged.size()) / 2;
  for (size_t i = middle; i < middle + 40; ++i) damaged[i] = static_cast<uint8_t>(0xFF - (i % 7));
  const fs::path p = Write("damaged.jpg", damaged);
  ASSERT_FALSE(cv::imread(p.string()).empty()) << "this libjpeg no longer decodes damaged data: the check is moot";
  std::string why;
  EXPECT_TRUE(ReadImageFile(p, cv::IMREAD_GRAYSCALE, &why).empty());
  EXPECT_NE(why.find("JPEG data corrupt: Corrupt JPEG data"), std::string::npos) << why;
  EXPECT_EQ(JpegDataProblem(jpeg_.data(), jpeg_.size()), "");  // the undamaged file
}

// What a Logitech C270 sends on every MJPEG frame, saved to a file: a few bytes before a restart
// marker. libjpeg warns of "3 extraneous bytes" and decodes the picture whole; the live decoder
// publishes it, and a folder of such frames was refused frame by frame on replay.
TEST_F(ImageFileTest, ACamerasPaddingBeforeARestartMarkerReadsWhole) {
  cv::Mat picture(96, 128, CV_8UC3);
  cv::randu(picture, 0, 255);
  std::vector<uint8_t> restarts;
  ASSERT_TRUE(cv::imencode(".jpg", picture, restarts, {cv::IMWRITE_JPEG_QUALITY, 90, cv::IMWRITE_JPEG_RST_INTERVAL, 4}));
  const cv::Mat clean = cv::imdecode(restarts, cv::IMREAD_COLOR);
  size_t rst = 0;
  for (size_t i = 2; i + 1 < restarts.size() && rst == 0; ++i)
    if (restarts[i] == 0xFF && restarts[i + 1] >= 0xD0 && restarts[i + 1] <= 0xD7) rst = i;
  ASSERT_GT(rst, 0u);
  restarts.insert(restarts.begin() + static_cast<std::ptrdiff_t>(rst), {0x00, 0x17, 0x2a});
  std::string why;
  const cv::Mat read = ReadImageFile(Write("c270.jpg", restarts), cv::IMREAD_COLOR, &why);
  ASSERT_FALSE(read.empty()) << why;
  EXPECT_EQ(cv::norm(read, clean, cv::NORM_INF), 0.0);
}

TEST_F(ImageFileTest, AJpegClaimingAHugeImageIsRefusedFromItsHeader) {
  // A 64x48 file whose frame header says 40000x40000: libjpeg set aside the coefficients of the
  // size claimed (3 GB) before finding the data short. Refused from the header, as imread does.
  std::vector<uint8_t> claim = jpeg_;
  size_t sof = 0;
  for (size_t i = 2; i + 9 < claim.size(); ++i)
    if (claim[i] == 0xFF && (claim[i + 1] == 0xC0 || claim[i + 1] == 0xC2)) sof = i;
  ASSERT_GT(sof, 0u);
  for (const size_t at : {sof + 5, sof + 7}) {  // height, then width, big-endian
    claim[at] = 40000 >> 8;
    claim[at + 1] = 40000 & 0xFF;
  }
  std::string why;
  EXPECT_TRUE(ReadImageFile(Write("claim.jpg", claim), cv::IMREAD_GRAYSCALE, &why).empty());
  EXPECT_NE(why.find("its header claims 40000x40000 pixels"), std::string::npos) << why;
}

TEST_F(ImageFileTest, DecodeJpegBgrMatchesImdecodeAndKeepsLibjpegsComplaints) {
  // A clean JPEG: the same pixels as cv::imdecode's (both libjpeg-turbo, the same DCT). A damaged
  // one: libjpeg's warning, where imdecode hands back made-up blocks. A header claiming 40000 x
  // 40000: refused before any memory is set aside.
  cv::Mat ours;
  ASSERT_EQ(DecodeJpegBgr(jpeg_.data(), jpeg_.size(), &ours), "");
  const cv::Mat theirs = cv::imdecode(jpeg_, cv::IMREAD_COLOR);
  ASSERT_EQ(ours.type(), CV_8UC3);
  ASSERT_EQ(ours.size(), theirs.size());
  EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0);
  std::vector<uint8_t> damaged = jpeg_;
  size_t scan = 0;
  for (size_t i = 2; i + 1 < damaged.size(); ++i)
    if (damaged[i] == 0xFF && damaged[i + 1] == 0xDA) scan = i;
  const size_t middle = (scan + damaged.size()) / 2;
  for (size_t i = middle; i < middle + 40; ++i) damaged[i] = static_cast<uint8_t>(0xFF - (i % 7));
  ASSERT_FALSE(cv::imdecode(damaged, cv::IMREAD_COLOR).empty());
  EXPECT_NE(DecodeJpegBgr(damaged.data(), damaged.size(), &ours).find("Corrupt JPEG data"), std::string::npos);
  std::vector<uint8_t> claim = jpeg_;
  size_t sof = 0;
  for (size_t i = 2; i + 9 < claim.size(); ++i)
    if (claim[i] == 0xFF && (claim[i + 1] == 0xC0 || claim[i + 1] == 0xC2)) sof = i;
  for (const size_t at : {sof + 5, sof + 7}) {
    claim[at] = 40000 >> 8;
    claim[at + 1] = 40000 & 0xFF;
  }
  EXPECT_NE(DecodeJpegBgr(claim.data(), claim.size(), &ours).find("40000x40000"), std::string::npos);
  const std::vector<uint8_t> garbage = {0xFF, 0xD8, 0xFF, 0xDA, 0x12, 0x34, 0xFF, 0xD9};
  EXPECT_NE(DecodeJpegBgr(garbage.data(), garbage.size(), &ours), "");
}

TEST_F(ImageFileTest, AJpegCutShortIsRefusedWhereImreadMakesRowsUp) {
  std::vector<uint8_t> cut(jpeg_.begin(), jpeg_.begin() + jpeg_.size() / 2);
  const fs::path p = Write("cut.jpg", cut);
  ASSERT_FALSE(cv::imread(p.string()).empty()) << "this libjpeg no longer decodes a cut JPEG: the check is moot";
  std::string why;
  EXPECT_TRUE(ReadImageFile(p, cv::IMREAD_COLOR, &why).empty());
  EXPECT_NE(why.find("JPEG truncated"), std::string::npos) << why;
  // Zeros after the end marker (padding) are whole.
  std::vector<uint8_t> padded = jpeg_;
  padded.resize(padded.size() + 64, 0);
  EXPECT_FALSE(ReadImageFile(Write("padded.jpg", padded), cv::IMREAD_COLOR, &why).empty()) << why;
  // Nor is a trailer after it (phones append their own data), which imread reads whole too.
  std::vector<uint8_t> trailed = jpeg_;
  const std::string trailer = "SEFHDR\xFF\xD8 more vendor data";
  trailed.insert(trailed.end(), trailer.begin(), trailer.end());
  ASSERT_FALSE(cv::imread(Write("trailed.jpg", trailed).string()).empty());
  EXPECT_FALSE(ReadImageFile(dir_ / "trailed.jpg", cv::IMREAD_COLOR, &why).empty()) << why;
  // A trailer holding FF DA and no FF D9 after it (a Motion Photo's MP4): it was taken for the
  // last scan, and the photo refused as truncated.
  std::vector<uint8_t> motion = jpeg_;
  const uint8_t mp4_bytes[] = {0x00, 0x00, 0x00, 0x18, 'f', 't', 'y', 'p', 0xFF, 0xDA, 0x00, 0x08, 0x12};
  motion.insert(motion.end(), mp4_bytes, mp4_bytes + sizeof(mp4_bytes));
  EXPECT_EQ(JpegWholeness(motion.data(), motion.size()), "");
  EXPECT_FALSE(ReadImageFile(Write("motion.jpg", motion), cv::IMREAD_COLOR, &why).empty()) << why;
  // A cut inside the header segments, before any scan.
  const std::vector<uint8_t> header_cut(jpeg_.begin(), jpeg_.begin() + 30);
  EXPECT_NE(JpegWholeness(header_cut.data(), header_cut.size()).find("no start-of-scan"), std::string::npos)
      << JpegWholeness(header_cut.data(), header_cut.size());
  // A cut that keeps a thumbnail's end marker ahead of the main scan is still cut: the marker
  // must follow the last scan.
  std::vector<uint8_t> early_end(jpeg_.begin(), jpeg_.begin() + 2);
  const uint8_t thumbnail_like[] = {0xFF, 0xD9};
  early_end.insert(early_end.end(), thumbnail_like, thumbnail_like + 2);
  early_end.insert(early_end.end(), jpeg_.begin() + 2, jpeg_.begin() + jpeg_.size() / 2);
  EXPECT_TRUE(ReadImageFile(Write("early_end.jpg", early_end), cv::IMREAD_COLOR, &why).empty());
  EXPECT_NE(why.find("after its last scan"), std::string::npos) << why;
}

TEST_F(ImageFileTest, OtherFormatsAndBadFilesSayWhy) {
  std::vector<uint8_t> png;
  cv::imencode(".png", image_, png);
  std::string why;
  const cv::Mat read = ReadImageFile(Write("a.png", png), cv::IMREAD_COLOR, &why);
  ASSERT_FALSE(read.empty()) << why;
  EXPECT_EQ(cv::norm(read, image_, cv::NORM_INF), 0.0);  // lossless
  EXPECT_TRUE(ReadImageFile(dir_ / "missing.png", cv::IMREAD_COLOR, &why).empty());
  EXPECT_EQ(why, "cannot read");
  EXPECT_TRUE(ReadImageFile(Write("empty.png", {}), cv::IMREAD_COLOR, &why).empty());
  EXPECT_NE(why.find("empty file"), std::string::npos) << why;
  // A folder where a frame should be: it threw "basic_filebuf::underflow" naming no file.
  std::filesystem::create_directories(dir_ / "000.jpg");
  EXPECT_TRUE(ReadImageFile(dir_ / "000.jpg", cv::IMREAD_COLOR, &why).empty());
  EXPECT_EQ(why, "is a folder, not an image");
  const std::string text = "not an image at all";
  EXPECT_TRUE(ReadImageFile(Write("text.png", std::vector<uint8_t>(text.begin(), text.end())), cv::IMREAD_COLOR, &why)
                  .empty());
  EXPECT_NE(why.find("not a readable image"), std::string::npos) << why;
  // A PGM header claiming more pixels than OpenCV allows throws inside OpenCV: an error, not a crash.
  const std::string bomb = "P5\n100000 100000\n255\n";
  EXPECT_TRUE(ReadImageFile(Write("bomb.pgm", std::vector<uint8_t>(bomb.begin(), bomb.end())), cv::IMREAD_GRAYSCALE,
                            &why).empty());
  EXPECT_NE(why.find("not a readable image"), std::string::npos) << why;
}

}  // namespace
}  // namespace clothwind::common
