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
#include <tuple>
#include <type_traits>
#include <vector>

#include <sys/wait.h>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
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
  // Resolved names, as `rosbag record` (field.launch) stores them: `rosbag play --topics
  // /camera/image_raw` and `rosbag filter` then treat both alike.
  EXPECT_EQ(c.types.at("/camera/image_raw"), "sensor_msgs/Image");
  EXPECT_EQ(c.types.at("/camera/camera_info"), "sensor_msgs/CameraInfo");
  EXPECT_EQ(c.types.at("/anemometer/raw"), "clothwind/RawSentence");
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
  // Runs make-session with `args`; expects it refused, no bag left, and returns what it said.
  auto refused = [&dir](const std::string& args) {
    const fs::path bag = dir / "bad.bag";
    const std::string log = (dir / "log").string();
    const std::string cmd =
        std::string(CLOTHWIND_BIN) + " make-session " + args + " --out " + bag.string() + " > " + log + " 2>&1";
    EXPECT_NE(std::system(cmd.c_str()), 0) << cmd;
    EXPECT_FALSE(fs::exists(bag)) << args;
    std::ifstream in(log);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  // Each refused naming --minutes: inf, nan and 1e30 were refused by other checks (the finite-number
  // check, --start-time's), so the bound itself went untested; 0.04 and 1441 only it refuses.
  for (const char* minutes : {"inf", "nan", "0.0001", "1e30", "0.04", "1441"}) {
    const std::string text = refused(std::string("--minutes ") + minutes);
    EXPECT_NE(text.find("--minutes"), std::string::npos) << minutes << ": " << text;
  }
  EXPECT_NE(refused("--minutes 0.04").find("--minutes must be in 0.05..1440"), std::string::npos);
  // A camera too slow for a clip (every interval a hole; at 10 fps its jitter makes half of them
  // holes, and no stretch lasts a clip), nearly every frame dropped (no images),
  // a start so early a frame's jitter put it before time 0 (failed mid-write for some seeds).
  for (const char* args : {"--fps 8", "--fps 10", "--drop-probability 0.9999", "--start-time 0.001 --seed 3"}) {
    const std::string text = refused(std::string("--minutes 0.1 ") + args);
    EXPECT_TRUE(text.find("--fps") != std::string::npos || text.find("frames") != std::string::npos ||
                text.find("--start-time") != std::string::npos) << args << ": " << text;
  }
  // An empty frame id: every message carries one (refused by clothwind for any option's empty value).
  for (const char* option : {"--camera-frame", "--anemometer-frame"}) {
    const std::string text = refused(std::string("--minutes 0.1 ") + option + " ''");
    EXPECT_NE(text.find(std::string(option) + ": an empty value"), std::string::npos) << text;
  }
  fs::remove_all(dir);
}

TEST(SessionBagTest, APreviewOrZetaSeedItCannotUseIsRefusedBeforeTheWork) {
  // A preview OpenCV cannot write was ignored after the whole session (imwrite's result was not
  // read); a negative --zeta-seed was taken as "the session's seed".
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_opts_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string bag = (dir / "bad.bag").string(), log = (dir / "log").string();
  for (const std::string& args : {"--preview " + (dir / "first.notanimage").string(),
                                 // (a missing folder is made, as --out's; one that takes no file is refused)
                                 std::string("--preview /proc/first.png"),
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

TEST(SessionBagTest, SettingsOfARenderedSessionAreRefusedForAProceduralOne) {
  // Accepted and ignored: a procedural bag came out of a command given a rendered one's settings.
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_procedural_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string bag = (dir / "bad.bag").string(), log = (dir / "log").string();
  for (const std::string option : {"--zeta-seed 3", "--render-samples 2", "--max-edge 0.5", "--warmup 1",
                                   "--camera-distance 5"}) {
    for (const std::string frames : {"", " --frames procedural"}) {
      const std::string cmd = std::string(CLOTHWIND_BIN) + " make-session --minutes 0.05 --out " + bag + frames + " " +
                              option + " > " + log + " 2>&1";
      EXPECT_NE(std::system(cmd.c_str()), 0) << cmd;
      EXPECT_FALSE(fs::exists(bag)) << cmd;
      std::ifstream in(log);
      const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      EXPECT_NE(text.find(option.substr(0, option.find(' ')) + " is a setting of --frames rendered"), std::string::npos)
          << cmd << ": " << text;
    }
  }
  fs::remove_all(dir);
}

TEST(SessionBagTest, AnExistingOutOrAFolderIsRefusedBeforeTheWork) {
  // An existing bag (perhaps a recorded field session) was replaced without a word, and a folder
  // failed only at the final rename, the finished session discarded.
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_out_" + std::to_string(::getpid()));
  fs::create_directories(dir / "a_folder");
  const fs::path bag = dir / "recorded.bag";
  std::ofstream(bag) << "a field session";
  const std::string log = (dir / "log").string();
  auto run = [&](const std::string& out, const std::string& extra) {
    const std::string cmd = std::string(CLOTHWIND_BIN) + " make-session --minutes 0.05 --out " + out + extra +
                            " > " + log + " 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream in(log);
    return std::make_pair(status, std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  };
  auto [status, text] = run(bag.string(), "");
  EXPECT_NE(status, 0);
  EXPECT_NE(text.find("--out " + bag.string() + " exists"), std::string::npos) << text;
  EXPECT_NE(text.find("--overwrite"), std::string::npos) << text;
  std::ifstream kept(bag);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(kept)), std::istreambuf_iterator<char>()), "a field session");
  std::tie(status, text) = run((dir / "a_folder").string(), "");
  EXPECT_NE(status, 0);
  EXPECT_NE(text.find("is a folder"), std::string::npos) << text;
  EXPECT_EQ(text.find("frames"), std::string::npos) << "refused before the work: " << text;
  // A name ending in a slash (a folder not made yet) or none: refused before the work too (the
  // session was made, then the rename failed, leaving the folder made and empty).
  for (const std::string& out : {(dir / "new_folder").string() + "/", std::string("''")}) {
    std::tie(status, text) = run(out, "");
    EXPECT_NE(status, 0);
    EXPECT_NE(text.find(out == "''" ? "--out: an empty value" : "expected a bag file name"), std::string::npos) << text;
  }
  EXPECT_FALSE(fs::exists(dir / "new_folder"));
  std::tie(status, text) = run(bag.string(), " --overwrite");
  EXPECT_EQ(status, 0) << text;
  EXPECT_GT(fs::file_size(bag), 1000u);
  fs::remove_all(dir);
}

TEST(SessionBagTest, AFullDiskIsAnErrorAndLeavesNoPartialBag) {
  // A write that fails (file size limit: the disk full) threw again from the bag's close() in the
  // cleanup and again from its destructor: std::terminate (exit 134) with the temporary bag left.
  const fs::path dir = fs::temp_directory_path() / ("clothwind_session_full_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path bag = dir / "full.bag";
  const std::string cmd = "bash -c 'trap \"\" XFSZ; ulimit -f 2000; exec " + std::string(CLOTHWIND_BIN) +
                          " make-session --minutes 0.5 --out " + bag.string() + "' > " + (dir / "log").string() +
                          " 2>&1";
  const int status = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << cmd;
  EXPECT_EQ(WEXITSTATUS(status), 1) << cmd;
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_TRUE(e.path().filename() == "log") << "left behind: " << e.path();
  std::ifstream in(dir / "log");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(bag.string()), std::string::npos) << text;
  fs::remove_all(dir);
}

// Writes `in` to `out` with each message passed through `edit` (which may change its stamp or
// contents, or return false to leave it out); `extra` messages are added on topic /diagnostics.
template <typename Edit>
void RewriteBag(const std::string& in, const std::string& out, Edit edit, bool extra = false) {
  rosbag::Bag src(in, rosbag::bagmode::Read), dst(out, rosbag::bagmode::Write);
  for (const rosbag::MessageInstance& m : rosbag::View(src)) {
    if (auto img = m.instantiate<sensor_msgs::Image>()) {
      if (edit(*img)) dst.write(m.getTopic(), m.getTime(), *img);
    } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      if (edit(*info)) dst.write(m.getTopic(), m.getTime(), *info);
    } else if (auto raw = m.instantiate<clothwind::RawSentence>()) {
      if (edit(*raw)) dst.write(m.getTopic(), m.getTime(), *raw);
      if (extra) dst.write("/diagnostics", m.getTime(), *raw);
    }
  }
}

// An NMEA MWV sentence flagged void (status V), its checksum made right again.
std::string VoidSentence(const std::string& sentence) {
  std::string body = sentence.substr(1, sentence.find('*') - 1);
  const size_t status = body.rfind(",A");
  if (status != std::string::npos) body[status + 1] = 'V';
  unsigned sum = 0;
  for (char c : body) sum ^= static_cast<unsigned char>(c);
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X", sum);
  return "$" + body + tail +
         (sentence.size() > 2 && sentence.substr(sentence.size() - 2) == "\r\n" ? "\r\n" : "");
}

TEST(SessionBagTest, BagCheckRefusesBagsTheReplayCannotUse) {
  // Each of these passed as "ok for replay", and the replay made no labelled clip (or hung).
  const std::string good = MakeSession("", "good.bag");
  const fs::path dir = fs::path(good).parent_path();
  struct Case {
    const char* name;
    const char* says;
  };
  auto check = [&](const std::string& bag) {
    const std::string log = bag + ".log";
    const int rc = std::system((std::string(CLOTHWIND_BIN) + " bag-check " + bag + " > " + log + " 2>&1").c_str());
    std::ifstream in(log);
    return std::make_pair(rc, std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  };
  ASSERT_EQ(check(good).first, 0) << check(good).second;
  const std::string ahead = (dir / "ahead.bag").string(), zero = (dir / "zero.bag").string(),
                    checksum = (dir / "checksum.bag").string(), extra = (dir / "extra.bag").string(),
                    slow = (dir / "slow.bag").string(), apart = (dir / "apart.bag").string();
  // Camera stamps a minute ahead of their bag times (the clip buffer refuses them as future).
  RewriteBag(good, ahead, [](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, sensor_msgs::Image>) m.header.stamp += ros::Duration(60);
    return true;
  });
  // Anemometer sentences stamped 0.
  RewriteBag(good, zero, [](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, clothwind::RawSentence>) m.header.stamp = ros::Time();
    return true;
  });
  // Every sentence with a wrong checksum.
  RewriteBag(good, checksum, [](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, clothwind::RawSentence>)
      m.data = m.data.substr(0, m.data.find('*')) + "*00";
    return true;
  });
  // A topic no replay node reads (rosbag record -a): replay.launch would wait for it for ever.
  RewriteBag(good, extra, [](auto&) { return true; }, true);
  // One camera frame in four kept: 7.5 fps, every interval (0.13 s) a hole to the clip buffer.
  int k = 0;
  RewriteBag(good, slow, [&](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, sensor_msgs::Image>) return k++ % 4 == 0;
    return true;
  });
  // Anemometer stamps (and bag times) shifted: a day before the camera's (another time base),
  // and 20 s after its last frame (each clip's label window ends at its last frame: a symmetric
  // overlap check passed this one, which replayed into 25 clips, none labelled).
  auto shift_anemometer = [&](const std::string& out, double seconds) {
    rosbag::Bag src(good, rosbag::bagmode::Read), dst(out, rosbag::bagmode::Write);
    for (const rosbag::MessageInstance& m : rosbag::View(src)) {
      if (auto raw = m.instantiate<clothwind::RawSentence>()) {
        raw->header.stamp += ros::Duration(seconds);
        dst.write(m.getTopic(), raw->header.stamp, *raw);
      } else if (auto img = m.instantiate<sensor_msgs::Image>()) {
        dst.write(m.getTopic(), m.getTime(), *img);
      } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
        dst.write(m.getTopic(), m.getTime(), *info);
      }
    }
  };
  shift_anemometer(apart, -86400);
  // The camera recorded compressed (image_transport's compressed topic renamed): clip_buffer
  // subscribes to sensor_msgs/Image and would receive nothing.
  {
    rosbag::Bag src(good, rosbag::bagmode::Read), dst((dir / "compressed.bag").string(), rosbag::bagmode::Write);
    for (const rosbag::MessageInstance& m : rosbag::View(src)) {
      if (auto img = m.instantiate<sensor_msgs::Image>()) {
        sensor_msgs::CompressedImage c;
        c.header = img->header;
        c.format = "jpeg";
        c.data.assign(16, 0);
        dst.write(m.getTopic(), m.getTime(), c);
      } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
        dst.write(m.getTopic(), m.getTime(), *info);
      } else if (auto raw = m.instantiate<clothwind::RawSentence>()) {
        dst.write(m.getTopic(), m.getTime(), *raw);
      }
    }
  }
  shift_anemometer((dir / "after.bag").string(), 6 + 20);  // the session is 6 s long
  // Usable readings only before and after the video, void ones during it: the first sentence
  // 100 s earlier (past the 60 s label window of the first clip), the last 30 s after the last
  // frame, the three between flagged void. Comparing only the earliest and latest usable stamps
  // with the clips' windows passed it, and no clip got a label.
  {
    rosbag::Bag src(good, rosbag::bagmode::Read), dst((dir / "around.bag").string(), rosbag::bagmode::Write);
    int sentence = 0;
    for (const rosbag::MessageInstance& m : rosbag::View(src)) {
      if (auto raw = m.instantiate<clothwind::RawSentence>()) {
        const int k = sentence++;
        if (k == 0) raw->header.stamp -= ros::Duration(100);
        else if (k == 4) raw->header.stamp += ros::Duration(30);
        else raw->data = VoidSentence(raw->data);
        dst.write(m.getTopic(), raw->header.stamp, *raw);
      } else if (auto img = m.instantiate<sensor_msgs::Image>()) {
        dst.write(m.getTopic(), m.getTime(), *img);
      } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
        dst.write(m.getTopic(), m.getTime(), *info);
      }
    }
    ASSERT_EQ(sentence, 5);
  }
  // Every header stamp 10 s behind its bag time (a camera's and an instrument's latency): the
  // clip buffer refuses only stamps ahead of the clock, and this bag replays into labelled clips.
  const std::string lagging = (dir / "lagging.bag").string();
  RewriteBag(good, lagging, [](auto& m) {
    m.header.stamp -= ros::Duration(10);
    return true;
  });
  EXPECT_EQ(check(lagging).first, 0) << check(lagging).second;
  // One camera frame repeating its predecessor's stamp, and one 20 ms early (a driver's
  // duplicate, a reordered frame): the nodes drop them and go on, so the bag is ok, with a
  // warning naming the first of each. (Both were refused.)
  const std::string hiccup = (dir / "hiccup.bag").string();
  int frame = 0;
  double previous = 0;
  RewriteBag(good, hiccup, [&](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, sensor_msgs::Image>) {
      const double t = m.header.stamp.toSec();
      if (frame == 50) m.header.stamp = ros::Time(previous);
      if (frame == 80) m.header.stamp = ros::Time(previous - 0.02);
      // A lone frame stamped 1 s back every 25 frames (0.83 s): the clip buffer drops each as
      // stale and goes on; counted as holes, no stretch lasted a clip and the bag was refused.
      if (frame % 25 == 12) m.header.stamp = ros::Time(t - 1.0);
      // And one stamped 1 s ahead (two holes each, and the next frame read as going back).
      if (frame % 25 == 7) m.header.stamp = ros::Time(t + 1.0);  // (not 5: frame 80 is the early one)
      // One frame 10 s ahead of its bag time (the clip buffer's ~max_future refuses it alone).
      if (frame == 100) m.header.stamp = ros::Time(t + 10.0);
      previous = t;
      ++frame;
    }
    return true;
  });
  {
    const auto [rc, out] = check(hiccup);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("warning: camera/image_raw: 1 frames repeat a stamp (the first at message"), std::string::npos)
        << out;
    EXPECT_NE(out.find("header stamps go back (the first at message"), std::string::npos) << out;
    EXPECT_NE(out.find("dropped as stale (7 here)"), std::string::npos) << out;
    EXPECT_NE(out.find("lone frames stamped more than the gap tolerance ahead of the next"), std::string::npos) << out;
    EXPECT_NE(out.find("warning: camera/image_raw: 0 messages stamped 0 and 1 more than"), std::string::npos) << out;
  }
  // camera_info stamped 0 throughout (the clip buffer reads no stamp of it), and one sentence
  // stamped 0: the bag replays whole (both were refused).
  const std::string info_zero = (dir / "info_zero.bag").string();
  int sentences = 0;
  RewriteBag(good, info_zero, [&](auto& m) {
    using T = std::decay_t<decltype(m)>;
    if constexpr (std::is_same_v<T, sensor_msgs::CameraInfo>) m.header.stamp = ros::Time();
    if constexpr (std::is_same_v<T, clothwind::RawSentence>)
      if (sentences++ == 2) m.header.stamp = ros::Time();
    return true;
  });
  {
    const auto [rc, out] = check(info_zero);
    EXPECT_EQ(rc, 0) << out;
    EXPECT_NE(out.find("warning: anemometer/raw: 1 messages stamped 0"), std::string::npos) << out;
  }
  // One sentence with a bad checksum, the rest stamped 0: no reading labels a clip, though neither
  // rule alone fails the bag (not every message is dropped, none is void). It passed.
  int wind_sentence = 0;
  RewriteBag(good, (dir / "zero_wind.bag").string(), [&](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, clothwind::RawSentence>) {
      if (wind_sentence++ == 0) m.data = m.data.substr(0, m.data.find('*')) + "*00";
      else m.header.stamp = ros::Time();
    }
    return true;
  });
  // Frames the clip buffer cannot read (an encoding it cannot convert), and sentences recorded
  // 40 s after their stamps (replayed after every clip of this 6 s session went out): both passed.
  RewriteBag(good, (dir / "float.bag").string(), [](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, sensor_msgs::Image>) m.encoding = "32FC1";
    return true;
  });
  {
    rosbag::Bag src(good, rosbag::bagmode::Read), dst((dir / "late.bag").string(), rosbag::bagmode::Write);
    for (const rosbag::MessageInstance& m : rosbag::View(src)) {
      if (auto raw = m.instantiate<clothwind::RawSentence>()) {
        dst.write(m.getTopic(), raw->header.stamp + ros::Duration(40), *raw);
      } else if (auto img = m.instantiate<sensor_msgs::Image>()) {
        dst.write(m.getTopic(), m.getTime(), *img);
      } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
        dst.write(m.getTopic(), m.getTime(), *info);
      }
    }
  }
  // Every anemometer sentence flagged void (NMEA status V, its checksum right): decoded, and no
  // clip labelled by any. (It passed as "ok for replay".)
  const std::string void_bag = (dir / "void.bag").string();
  RewriteBag(good, void_bag, [](auto& m) {
    if constexpr (std::is_same_v<std::decay_t<decltype(m)>, clothwind::RawSentence>) m.data = VoidSentence(m.data);
    return true;
  });
  // A file that is no bag at all: said so, without the repair hint for a bag cut short.
  const std::string text_file = (dir / "notes.bag").string();
  std::ofstream(text_file) << "hello\n";
  {
    const auto [rc, out] = check(text_file);
    EXPECT_NE(rc, 0) << out;
    EXPECT_NE(out.find("not a rosbag file"), std::string::npos) << out;
    EXPECT_EQ(out.find("rosbag reindex"), std::string::npos) << out;
  }
  for (const Case& c : {Case{"ahead.bag", "ahead of their bag time"}, Case{"zero.bag", "stamped 0"},
                        Case{"checksum.bag", "no sentence gives a wind reading"},
                        Case{"void.bag", "no reading the clip buffer can label with: 5 void"},
                        Case{"zero_wind.bag", "no reading the clip buffer can label with: 0 void"},
                        Case{"extra.bag", "wait:=false"}, Case{"slow.bag", "no stretch of frames without a hole"},
                        Case{"apart.bag", "falls in a clip's label window"},
                        Case{"after.bag", "falls in a clip's label window"},
                        Case{"around.bag", "falls in a clip's label window"},
                        Case{"float.bag", "frames the clip buffer cannot read"},
                        Case{"late.bag", "is recorded before that clip is labelled"},
                        Case{"compressed.bag", "recorded as sensor_msgs/CompressedImage, the replay subscribes to it "
                                               "as sensor_msgs/Image"}}) {
    const auto [rc, out] = check((dir / c.name).string());
    EXPECT_EQ(rc, 1 << 8) << c.name << ": " << out;
    EXPECT_NE(out.find(c.says), std::string::npos) << c.name << ": " << out;
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
  // Cut after its first chunks (no index at the end): rosbag says "Error reading from file";
  // the repair is named too.
  fs::copy_file(bag, dir / "cut-late.bag");
  fs::resize_file(dir / "cut-late.bag", fs::file_size(bag) * 3 / 4);
  {
    const auto [rc, out] = check((dir / "cut-late.bag").string(), "cut-late");
    EXPECT_NE(rc, 0);
    EXPECT_NE(out.find("rosbag reindex"), std::string::npos) << out;
  }
  // One frame whose data length overruns the record: a bare "Buffer Overrun" named nothing.
  {
    const std::string plain = (dir / "uncompressed.bag").string();  // the session's chunks are LZ4
    RewriteBag(bag, plain, [](auto&) { return true; });
    std::ifstream in(plain, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string encoding("\x04\x00\x00\x00" "bgr8", 8);
    const size_t at = bytes.find(encoding);
    ASSERT_NE(at, std::string::npos);
    const size_t length = at + encoding.size() + 1 + 4;  // is_bigendian (1 byte), step (4), then data's length
    const uint32_t huge = 0x7FFFFFF0u;
    bytes.replace(length, 4, reinterpret_cast<const char*>(&huge), 4);
    std::ofstream(dir / "overrun.bag", std::ios::binary) << bytes;
    const auto [rc, out] = check((dir / "overrun.bag").string(), "overrun");
    EXPECT_NE(rc, 0);
    EXPECT_NE(out.find((dir / "overrun.bag").string() + ": message 1 of the bag (on /camera/image_raw) (sensor_msgs/Image"),
              std::string::npos)
        << out;
  }
  const auto [rc, out] = check(bag + " --gap-tolerance nan", "nan");
  EXPECT_NE(rc, 0);
  EXPECT_NE(out.find("--gap-tolerance"), std::string::npos) << out;
  EXPECT_EQ(check(bag, "whole").first, 0);
  fs::remove_all(dir);
}

}  // namespace
