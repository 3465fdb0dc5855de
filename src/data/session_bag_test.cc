// `clothwind make-session` writes what the live nodes publish: topics, types, rates and stamps,
// for the rendered flag (simulated + rendered, anemometer sensor model) and the procedural one.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <clothwind/RawSentence.h>

namespace {

namespace fs = std::filesystem;

struct BagContents {
  std::map<std::string, std::string> types;  // topic -> datatype
  std::vector<double> image_stamps, info_stamps, wind_stamps;
  std::vector<std::string> sentences;
  std::vector<sensor_msgs::Image> images;
  bool stamps_match_bag_time = true;
};

BagContents ReadBag(const std::string& path) {
  BagContents c;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  rosbag::View view(bag);
  for (const rosbag::MessageInstance& m : view) {
    c.types[m.getTopic()] = m.getDataType();
    const double bag_time = m.getTime().toSec();
    double stamp = NAN;
    if (auto img = m.instantiate<sensor_msgs::Image>()) {
      stamp = img->header.stamp.toSec();
      c.image_stamps.push_back(stamp);
      if (c.images.size() < 40) c.images.push_back(*img);
    } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      stamp = info->header.stamp.toSec();
      c.info_stamps.push_back(stamp);
    } else if (auto raw = m.instantiate<clothwind::RawSentence>()) {
      stamp = raw->header.stamp.toSec();
      c.wind_stamps.push_back(stamp);
      c.sentences.push_back(raw->data);
      EXPECT_EQ(raw->protocol, "nmea");
    }
    c.stamps_match_bag_time &= std::abs(stamp - bag_time) < 1e-6;
  }
  return c;
}

std::string MakeSession(const std::string& args, const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string bag = (dir / name).string();
  const std::string cmd = std::string(CLOTHWIND_BIN) + " make-session --minutes 0.1 --seed 3 --out " + bag +
                          " " + args + " > " + (dir / (name + ".log")).string() + " 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return bag;
}

void CheckSession(const BagContents& c, size_t frames) {
  EXPECT_EQ(c.types.at("camera/image_raw"), "sensor_msgs/Image");
  EXPECT_EQ(c.types.at("camera/camera_info"), "sensor_msgs/CameraInfo");
  EXPECT_EQ(c.types.at("anemometer/raw"), "clothwind/RawSentence");
  EXPECT_EQ(c.types.size(), 3u);
  EXPECT_TRUE(c.stamps_match_bag_time);
  // Camera: its native 30 fps with capture jitter, one camera_info per image.
  ASSERT_EQ(c.image_stamps.size(), frames);
  EXPECT_EQ(c.info_stamps, c.image_stamps);
  for (size_t i = 1; i < c.image_stamps.size(); ++i)
    EXPECT_NEAR(c.image_stamps[i] - c.image_stamps[i - 1], 1.0 / 30, 0.009) << i;
  EXPECT_NEAR(c.image_stamps.front(), 1700000000.0, 0.01);
  // Anemometer: 1 Hz, each sentence arriving 50 ms after its interval; valid NMEA checksums.
  ASSERT_EQ(c.wind_stamps.size(), 5u);  // 6 s session: sentences at 1.05 .. 5.05 s
  for (size_t k = 0; k < c.wind_stamps.size(); ++k) {
    EXPECT_NEAR(c.wind_stamps[k], 1700000000.0 + (k + 1) + 0.05, 1e-6);
    const std::string& s = c.sentences[k];
    ASSERT_EQ(s.rfind("$WIMWV,", 0), 0u) << s;
    uint8_t x = 0;
    const size_t star = s.find('*');
    ASSERT_NE(star, std::string::npos);
    for (size_t i = 1; i < star; ++i) x ^= static_cast<uint8_t>(s[i]);
    EXPECT_EQ(std::stoul(s.substr(star + 1), nullptr, 16), x) << s;
    double angle = 0, speed = 0;
    ASSERT_EQ(std::sscanf(s.c_str(), "$WIMWV,%lf,R,%lf,M,A", &angle, &speed), 2) << s;
    EXPECT_GE(speed, 0.0);
    EXPECT_LT(speed, 15.0);
    EXPECT_GE(angle, 0.0);
    EXPECT_LT(angle, 360.0);
  }
}

TEST(SessionBagTest, RenderedSessionHasTheLiveNodesTopicsRatesAndStamps) {
  const std::string bag = MakeSession(
      "--frames rendered --width 160 --height 120 --max-edge 0.5 --render-samples 1 --warmup 1", "rendered.bag");
  const BagContents c = ReadBag(bag);
  CheckSession(c, 180);
  ASSERT_FALSE(c.images.empty());
  const auto& first = c.images.front();
  EXPECT_EQ(first.encoding, "bgr8");
  EXPECT_EQ(first.width, 160u);
  EXPECT_EQ(first.height, 120u);
  EXPECT_EQ(first.step, 160u * 3);
  EXPECT_EQ(first.header.frame_id, "camera_optical_frame");
  // The flag moves: frames a second apart differ in many pixels.
  const auto& later = c.images.back();
  int changed = 0;
  for (size_t i = 0; i < first.data.size(); ++i) changed += std::abs(first.data[i] - later.data[i]) > 10;
  EXPECT_GT(changed, 100);
  fs::remove_all(fs::path(bag).parent_path());
}

TEST(SessionBagTest, ProceduralSessionStillWorks) {
  const fs::path preview = fs::temp_directory_path() / ("clothwind_preview_" + std::to_string(::getpid()) + ".png");
  const std::string bag = MakeSession("--frames procedural --preview " + preview.string(), "procedural.bag");
  const BagContents c = ReadBag(bag);
  CheckSession(c, 180);
  // The preview is the bag's first frame.
  const cv::Mat first = cv::imread(preview.string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(first.empty()) << preview;
  ASSERT_FALSE(c.images.empty());
  ASSERT_EQ(first.cols * 3, static_cast<int>(c.images.front().step));
  EXPECT_TRUE(std::equal(first.data, first.data + first.total() * 3, c.images.front().data.begin()));
  fs::remove(preview);
  fs::remove_all(fs::path(bag).parent_path());
}

TEST(SessionBagTest, ADurationThatMakesNoSessionIsRefused) {
  // Infinity (a frame count of undefined size) and a few milliseconds wrote an empty bag, exit 0.
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_bad_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* minutes : {"inf", "nan", "0.0001", "1e30"}) {
    const fs::path bag = dir / "bad.bag";
    const std::string cmd = std::string(CLOTHWIND_BIN) + " make-session --minutes " + minutes + " --out " +
                            bag.string() + " > " + (dir / "log").string() + " 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_FALSE(fs::exists(bag)) << minutes;
  }
  fs::remove_all(dir);
}

TEST(SessionBagTest, APreviewOrZetaSeedItCannotUseIsRefusedBeforeTheWork) {
  // A preview OpenCV cannot write was ignored after the whole session (imwrite's result was not
  // read); a negative --zeta-seed was taken as "the session's seed".
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_opts_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string bag = (dir / "bad.bag").string(), log = (dir / "log").string();
  for (const std::string args : {"--preview " + (dir / "first.notanimage").string(),
                                 "--preview " + (dir / "no_such_folder" / "first.png").string(),
                                 std::string("--frames rendered --zeta-seed -5")}) {
    const std::string cmd = std::string(CLOTHWIND_BIN) + " make-session --minutes 0.05 --out " + bag + " " + args +
                            " > " + log + " 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_FALSE(fs::exists(bag)) << args;
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(args.find("preview") != std::string::npos ? "--preview" : "--zeta-seed"), std::string::npos)
        << text;
  }
  fs::remove_all(dir);
}

TEST(SessionBagTest, BagCheckNamesADamagedBag) {
  // A bag cut short and an empty file: exit 1 with an error naming the bag (rosbag's own named
  // neither); a NaN gap tolerance is refused (it counted no holes).
  const std::string bag = MakeSession("", "whole.bag");
  const fs::path dir = fs::path(bag).parent_path();
  fs::copy_file(bag, dir / "cut.bag");
  fs::resize_file(dir / "cut.bag", 4096);
  std::ofstream(dir / "empty.bag").close();
  auto check = [&](const std::string& args, const std::string& name) {
    const std::string log = (dir / (name + ".check.log")).string();
    const int rc = std::system((std::string(CLOTHWIND_BIN) + " bag-check " + args + " > " + log + " 2>&1").c_str());
    std::ifstream in(log);
    const std::string out((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return std::make_pair(rc, out);
  };
  for (const char* name : {"cut.bag", "empty.bag"}) {
    const auto [rc, out] = check((dir / name).string(), name);
    EXPECT_NE(rc, 0) << name;
    EXPECT_NE(out.find((dir / name).string() + ": not a readable bag"), std::string::npos) << out;
  }
  const auto [rc, out] = check(bag + " --gap-tolerance nan", "nan");
  EXPECT_NE(rc, 0);
  EXPECT_NE(out.find("--gap-tolerance"), std::string::npos) << out;
  EXPECT_EQ(check(bag, "whole").first, 0);
  fs::remove_all(dir);
}

}  // namespace
