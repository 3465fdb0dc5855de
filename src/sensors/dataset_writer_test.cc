#include "sensors/dataset_writer.h"

#include <fcntl.h>
#include <linux/fs.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "common/scoped_file_size_limit.h"

namespace clothwind::sensors {
namespace {
namespace fs = std::filesystem;

class DatasetWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("clothwind_dataset_writer_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  static LabelledClip MakeClip(uint64_t sequence, double t0, int frames = 4) {
    LabelledClip c;
    c.clip.sequence = sequence;
    for (int i = 0; i < frames; ++i) {
      cv::Mat img(32, 32, CV_8UC1, cv::Scalar(40 * i + 20));
      c.clip.frames.push_back({i, t0 + i / 25.0, t0 + i / 25.0 + 0.003, img});
    }
    c.roi = {40, 0, 240};
    c.source_width = 320;
    c.source_height = 240;
    c.label = ComputeWindLabel({{t0 - 1.0, 3.0, 0.5, "nmea_mwv", "anemometer", false},
                                {t0, 5.0, 0.5, "nmea_mwv", "anemometer", false}},
                               t0 + 0.12, 60.0);
    return c;
  }

  // The writer's temporaries in root_: hidden clip folders (".<clip>.tmp-...") and files beside
  // the index ("index.json.tmp-..."). Names of live writers (this process's pid) included.
  std::set<std::string> Hidden() const {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(root_)) {
      const std::string n = e.path().filename().string();
      if (n == ".lock") continue;  // the writer's lock, there while one is open
      if (n[0] == '.' || n.find(".tmp-") != std::string::npos) names.insert(n);
    }
    return names;
  }

  static nlohmann::json Read(const fs::path& p) {
    std::ifstream in(p);
    return nlohmann::json::parse(in);
  }

  fs::path root_;
};

TEST_F(DatasetWriterTest, WritesFramesLabelAndIndex) {
  DatasetWriter w(root_.string(), 95);
  const std::string dir =
      w.Write(MakeClip(3, 1700000000.5), {"camera_optical_frame", "test", nullptr, "test", "anemometer"});
  EXPECT_EQ(fs::path(dir).filename().string(), "clip-20231114-221320.500");
  for (int i = 0; i < 4; ++i) {
    char name[16];
    std::snprintf(name, sizeof name, "%03d.jpg", i);
    const cv::Mat img = cv::imread((fs::path(dir) / name).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(img.empty()) << name;
    EXPECT_EQ(img.type(), CV_8UC1);
    EXPECT_NEAR(img.at<uint8_t>(16, 16), 40 * i + 20, 2);  // JPEG round trip of a flat image
  }
  const auto label = Read(fs::path(dir) / "label.json");
  EXPECT_EQ(label["format"], "clothwind-clip");
  EXPECT_EQ(label["num_frames"], 4);
  EXPECT_DOUBLE_EQ(label["wind"]["mean"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(label["wind_speed"].get<double>(), 4.0);
  EXPECT_DOUBLE_EQ(label["wind"]["std"].get<double>(), 1.0);
  EXPECT_EQ(label["wind"]["count"], 2);
  EXPECT_EQ(label["wind"]["sources"],
            nlohmann::json::parse(R"([{"source": "nmea_mwv", "frame_id": "anemometer", "count": 2}])"));
  EXPECT_EQ(label["wind"]["relative_count"], 0);
  EXPECT_EQ(label["wind"]["direction_frame_id"], "anemometer");
  EXPECT_EQ(label["roi"]["x"], 40);
  EXPECT_EQ(label["source"]["frame_id"], "camera_optical_frame");
  EXPECT_NEAR(label["frame_stamps"][3].get<double>() - label["frame_stamps"][0].get<double>(), 0.12, 1e-6);
  // The camera's own stamps beside the resampled ones (3 ms apart here), the roi and the source's
  // size, each from its own field (none was read: a copy of the resampled stamps passed).
  EXPECT_NEAR(label["source_frame_stamps"][0].get<double>() - label["frame_stamps"][0].get<double>(), 0.003, 1e-6);
  EXPECT_EQ(label["roi"]["y"], 0);
  EXPECT_EQ(label["roi"]["size"], 240);
  EXPECT_EQ(label["source"]["width"], 320);
  EXPECT_EQ(label["source"]["height"], 240);
  EXPECT_DOUBLE_EQ(label["start"].get<double>(), 1700000000.5);
  EXPECT_NEAR(label["end"].get<double>(), 1700000000.5 + 3 / 25.0, 1e-9);
  const auto index = Read(root_ / "index.json");
  ASSERT_EQ(index["clips"].size(), 1u);
  EXPECT_EQ(index["clips"][0]["name"], fs::path(dir).filename().string());
  EXPECT_EQ(index["clips"][0]["wind_std"], label["wind"]["std"]);
  EXPECT_EQ(index["clips"][0]["wind_count"], 2);
  EXPECT_EQ(index["clips"][0]["start"], label["start"]);
  EXPECT_EQ(index["clips"][0]["end"], label["end"]);
  EXPECT_EQ(index["clips"][0]["split"], "test");
  EXPECT_EQ(index["kind"], "real");
  EXPECT_EQ(label["kind"], "real");
  // Nothing temporary is left behind.
  for (const auto& e : fs::directory_iterator(root_))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();
}

TEST_F(DatasetWriterTest, InvalidUtf8InTheSourceIsWrittenReplacedNotThrown) {
  // A camera's frame_id of raw bytes threw nlohmann's type_error 316 and stopped every later
  // clip's recording.
  DatasetWriter w(root_.string(), 95);
  const std::string dir =
      w.Write(MakeClip(4, 1700000001.0), {"cam\xff\xfe", "test", nullptr, "test", "anemometer"});
  const auto label = Read(fs::path(dir) / "label.json");
  EXPECT_EQ(label["source"]["frame_id"], "cam\xef\xbf\xbd\xef\xbf\xbd");  // U+FFFD twice
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 1u);
}

TEST_F(DatasetWriterTest, ColourClipsAreColourJpegsLabelledRgb8) {
  LabelledClip c = MakeClip(5, 1700000000.5, 2);
  for (auto& f : c.clip.frames) f.image = cv::Mat(32, 32, CV_8UC3, cv::Scalar(30, 90, 200));
  DatasetWriter w(root_.string(), 95);
  const std::string dir = w.Write(c, {"camera_optical_frame", "test", nullptr, "test", ""});
  const cv::Mat img = cv::imread((fs::path(dir) / "001.jpg").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(img.type(), CV_8UC3);
  const cv::Vec3b px = img.at<cv::Vec3b>(16, 16);
  EXPECT_NEAR(px[0], 30, 3);
  EXPECT_NEAR(px[1], 90, 3);
  EXPECT_NEAR(px[2], 200, 3);
  // The dataset format's name for colour JPEG frames, as FlagSim's: what learn::ReadDataset takes.
  EXPECT_EQ(Read(fs::path(dir) / "label.json")["encoding"], "rgb8");
  EXPECT_EQ(Read(fs::path(w.Write(MakeClip(6, 1700000010.5), {"", "test", nullptr, "test", ""})) / "label.json")["encoding"],
            "mono8");
}

TEST_F(DatasetWriterTest, ReopenAppendsAndRewriteReplaces) {
  {
    DatasetWriter w(root_.string());
    w.Write(MakeClip(0, 1700000000.0), {});
    w.Write(MakeClip(1, 1700000001.2), {});
  }
  DatasetWriter again(root_.string());
  EXPECT_EQ(again.size(), 2u);
  // The same clip replayed: replaced, not duplicated, though its sequence number differs (a bag
  // looped into a running clip buffer numbers each pass's clips on from the last).
  again.Write(MakeClip(41, 1700000001.2, 3), {});
  again.Write(MakeClip(2, 1700000002.4), {});
  EXPECT_EQ(again.size(), 3u);
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 3u);
  const auto replaced = Read(root_ / ClipFolderName(1700000001.2) / "label.json");
  EXPECT_EQ(replaced["num_frames"], 3);
  EXPECT_FALSE(fs::exists(root_ / ClipFolderName(1700000001.2) / "003.jpg"));
  int folders = 0;
  for (const auto& e : fs::directory_iterator(root_)) folders += e.is_directory();
  EXPECT_EQ(folders, 3);
}

// Another clip that starts in the same millisecond (the wall clock stepped back live, a new
// timeline over the old) is kept beside the first under a name of its own; it replaced it.
TEST_F(DatasetWriterTest, AnotherClipOfTheSameStartKeepsBoth) {
  DatasetWriter w(root_.string());
  const LabelledClip first = MakeClip(0, 1700000000.0);
  LabelledClip other = MakeClip(7, 1700000000.0);
  for (auto& f : other.clip.frames) f.source_stamp += 0.0004;  // another camera frame, same millisecond
  w.Write(first, {});
  const std::string second_path = w.Write(other, {});
  const std::string base = ClipFolderName(1700000000.0);
  EXPECT_EQ(fs::path(second_path).filename().string(), base + "-2");
  EXPECT_TRUE(fs::exists(root_ / base / "label.json"));
  EXPECT_EQ(Read(root_ / (base + "-2") / "label.json")["name"], base + "-2");
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 2u);
  // Each again (a replay of the session) replaces its own folder, and adds none.
  w.Write(other, {});
  w.Write(first, {});
  EXPECT_EQ(w.size(), 2u);
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 2u);
}

TEST_F(DatasetWriterTest, WithAnIndexIntervalClipsAreListedByTheNextRewriteFlushOrClose) {
  // index_interval a day: the first clip's write rewrites the index (none written yet, however
  // long the machine has been up: the steady clock starts at boot, so the clock here starts at
  // 1 s, a machine just booted, where "never written" read as "written at 0" kept the first clip
  // unlisted for a day), the next two are in place but unlisted until FlushIndex; the destructor
  // lists the last one. Every clip is recorded whole meanwhile, and a writer opening the folder
  // after a crash would list what the index lacks (ClipsInPlaceButNotListedAreIndexedOnOpen).
  {
    DatasetWriter w(root_.string(), 95, 86400.0, [] { return std::chrono::steady_clock::time_point(std::chrono::seconds(1)); });
    w.Write(MakeClip(0, 1700000000.0), {});
    EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 1u);
    EXPECT_EQ(w.unlisted(), 0u);
    w.Write(MakeClip(1, 1700000001.2), {});
    w.Write(MakeClip(2, 1700000002.4), {});
    EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 1u) << "rewritten before the interval passed";
    EXPECT_TRUE(fs::exists(root_ / ClipFolderName(1700000002.4) / "label.json"));
    EXPECT_EQ(w.unlisted(), 2u);
    EXPECT_EQ(w.size(), 3u);
    EXPECT_TRUE(w.FlushIndex());
    EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 3u);
    EXPECT_EQ(w.unlisted(), 0u);
    EXPECT_FALSE(w.FlushIndex()) << "nothing unlisted: no rewrite";
    w.Write(MakeClip(3, 1700000003.6), {});
    EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 3u);
  }
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 4u) << "the destructor lists the last clip";
  // Interval 0 (the default): every clip rewrites the index.
  DatasetWriter every(root_.string());
  every.Write(MakeClip(4, 1700000004.8), {});
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 5u);
  EXPECT_EQ(every.unlisted(), 0u);
  EXPECT_THROW(DatasetWriter(root_.string() + "-x", 95, -1.0), std::invalid_argument);
}

// Once index_interval has passed since the last rewrite, the next clip rewrites the index and
// lists the clips held back before it.
TEST_F(DatasetWriterTest, TheFirstClipAfterTheIntervalRewritesTheIndex) {
  auto now = std::make_shared<std::chrono::steady_clock::time_point>(std::chrono::seconds(5));
  DatasetWriter w(root_.string(), 95, 30.0, [now] { return *now; });
  w.Write(MakeClip(0, 1700000000.0), {});
  *now += std::chrono::seconds(29);
  w.Write(MakeClip(1, 1700000001.2), {});
  EXPECT_EQ(w.unlisted(), 1u) << "29 s after the last rewrite: held back";
  *now += std::chrono::seconds(2);
  w.Write(MakeClip(2, 1700000002.4), {});
  EXPECT_EQ(w.unlisted(), 0u) << "31 s: rewritten";
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 3u);
  *now += std::chrono::seconds(1);
  w.Write(MakeClip(3, 1700000003.6), {});
  EXPECT_EQ(w.unlisted(), 1u) << "the interval counts from that rewrite";
}

TEST_F(DatasetWriterTest, AClipReplacedWithinTheIndexIntervalIsListedAtOnce) {
  // A replay that replaces a clip changes its index entry; waiting for the interval left the old
  // entry on disk, and a crash then kept it for good (opening a folder lists missing clips, it
  // does not re-read those listed).
  DatasetWriter w(root_.string(), 95, 86400.0);
  w.Write(MakeClip(0, 1700000000.0), {});
  w.Write(MakeClip(1, 1700000001.2), {});
  EXPECT_EQ(w.unlisted(), 1u);
  w.Write(MakeClip(0, 1700000000.0, 3), {});  // replaced, 3 frames now
  EXPECT_EQ(w.unlisted(), 0u);
  const auto index = Read(root_ / "index.json");
  ASSERT_EQ(index["clips"].size(), 2u);
  int found = 0;
  for (const auto& c : index["clips"]) {
    if (c["name"] != ClipFolderName(1700000000.0)) continue;
    EXPECT_EQ(c["num_frames"], 3);
    ++found;
  }
  EXPECT_EQ(found, 1);
}

TEST_F(DatasetWriterTest, CorruptIndexIsAClearError) {
  fs::create_directories(root_);
  std::ofstream(root_ / "index.json") << "{ not json";
  try {
    DatasetWriter w(root_.string());
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("index.json"), std::string::npos);
  }
  // Valid JSON whose entries are not clips: each clip's index update failed after its folder was
  // written, so no clip ever reached the index.
  auto refusal = [&](const std::string& index) {
    std::ofstream(root_ / "index.json") << index;
    try {
      DatasetWriter w(root_.string());
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  std::string m = refusal(R"({"format": "clothwind-dataset", "clips": [1]})");
  EXPECT_NE(m.find("index.json: field 'clips[0]' must be an object with a string \"name\", got 1"), std::string::npos)
      << m;
  m = refusal(R"({"format": "clothwind-dataset", "clips": [{"name": "a"}, {"name": 3}]})");
  EXPECT_NE(m.find("'clips[1]'"), std::string::npos) << m;
  // A FlagSim dataset's index: real clips are not listed under its synthetic header.
  m = refusal(R"({"format": "clothwind-dataset", "kind": "flag", "clips": []})");
  EXPECT_NE(m.find("field 'kind' is \"flag\", expected \"real\""), std::string::npos) << m;
  EXPECT_EQ(refusal(R"({"format": "clothwind-dataset", "kind": "real", "clips": [{"name": "a"}]})"), "accepted");
}

TEST_F(DatasetWriterTest, AtomicFileWriteReplacesContent) {
  fs::create_directories(root_);
  const std::string p = (root_ / "a.txt").string();
  WriteFileAtomically(p, "one");
  WriteFileAtomically(p, "two");
  std::ifstream in(p);
  std::string s;
  in >> s;
  EXPECT_EQ(s, "two");
  EXPECT_THROW(WriteFileAtomically((root_ / "missing" / "b.txt").string(), "x"), std::runtime_error);
}

// A disk that fills up while a clip's replacement is written (RLIMIT_FSIZE stands in for a full
// disk: it fails writes even for root, where file permissions would not): the error names the
// file, the old copy and the index stay as they were and no temporary is left. (The put-back when
// the final rename fails is not provoked here: no fault can be injected between the two renames.)
TEST_F(DatasetWriterTest, FailedWriteKeepsTheOldCopyAndLeavesNoTemporary) {
  DatasetWriter w(root_.string());
  w.Write(MakeClip(0, 1700000000.0, 4), {});
  const auto index_before = Read(root_ / "index.json");
  const fs::path clip_dir = root_ / ClipFolderName(1700000000.0);

  std::string message;
  {
    const ScopedFileSizeLimit full_disk(64);  // bytes: smaller than any JPEG frame
    try {
      w.Write(MakeClip(0, 1700000000.0, 3), {});
    } catch (const std::exception& e) {
      message = e.what();
    }
  }

  EXPECT_NE(message.find("000.jpg"), std::string::npos) << message;
  EXPECT_EQ(Read(clip_dir / "label.json")["num_frames"], 4);  // the old copy, whole
  EXPECT_TRUE(fs::exists(clip_dir / "003.jpg"));
  EXPECT_EQ(Read(root_ / "index.json"), index_before);
  EXPECT_TRUE(Hidden().empty()) << *Hidden().begin();
}

// The index cannot be replaced (a folder stands in its place): the clip is recorded, the error
// says the index was not updated, and the next write's index lists both clips.
TEST_F(DatasetWriterTest, FailedIndexUpdateIsToldAndCaughtUpNextTime) {
  DatasetWriter w(root_.string());
  w.Write(MakeClip(0, 1700000000.0), {});
  fs::remove(root_ / "index.json");
  fs::create_directories(root_ / "index.json" / "blocker");
  std::string message;
  try {
    w.Write(MakeClip(1, 1700000001.2), {});
  } catch (const ClipRecordedWithAProblem& e) {  // recorded: not a failed write
    message = e.what();
  }
  EXPECT_NE(message.find("index.json not updated"), std::string::npos) << message;
  EXPECT_TRUE(fs::exists(root_ / ClipFolderName(1700000001.2) / "label.json"));
  EXPECT_TRUE(Hidden().empty()) << *Hidden().begin();
  fs::remove_all(root_ / "index.json");
  w.Write(MakeClip(2, 1700000002.4), {});
  EXPECT_EQ(Read(root_ / "index.json")["clips"].size(), 3u);
}

// A clip replayed again replaces its folder; the old copy cannot be removed (a file of it made
// immutable, which binds root, where permissions do not): the new clip is in place and listed, and
// the problem is said as the old copy's (it was a failed write, and the index kept the old entry).
TEST_F(DatasetWriterTest, AReplacedCopyThatCannotBeRemovedLeavesTheNewClipRecordedAndListed) {
  DatasetWriter w(root_.string());
  w.Write(MakeClip(0, 1700000000.0, 4), {});
  const fs::path clip_dir = root_ / ClipFolderName(1700000000.0);
  const fs::path pinned = clip_dir / "000.jpg";
  auto set_immutable = [](const fs::path& file, bool on) {
    const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    int flags = 0;
    bool ok = ::ioctl(fd, FS_IOC_GETFLAGS, &flags) == 0;
    flags = on ? (flags | FS_IMMUTABLE_FL) : (flags & ~FS_IMMUTABLE_FL);
    ok = ok && ::ioctl(fd, FS_IOC_SETFLAGS, &flags) == 0;
    ::close(fd);
    return ok;
  };
  if (!set_immutable(pinned, true)) GTEST_SKIP() << "cannot make a file immutable here (not root, or the filesystem)";
  std::string message;
  try {
    w.Write(MakeClip(0, 1700000000.0, 6), {});  // the same first frame: the same clip, replaced
    ADD_FAILURE() << "the old copy's removal failed and nothing was said";
  } catch (const ClipRecordedWithAProblem& e) {
    message = e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "the new clip counted as not recorded: " << e.what();
  }
  // Unpin the old copy (now under a hidden name) so that it, and the test's folder, can go.
  for (const auto& entry : fs::directory_iterator(root_))
    if (fs::exists(entry.path() / "000.jpg")) set_immutable(entry.path() / "000.jpg", false);
  EXPECT_NE(message.find("the copy it replaced"), std::string::npos) << message;
  EXPECT_EQ(Read(clip_dir / "label.json")["num_frames"], 6);  // the new copy in place
  const nlohmann::json index = Read(root_ / "index.json");
  ASSERT_EQ(index["clips"].size(), 1u);
  EXPECT_EQ(index["clips"][0]["num_frames"], 6) << index.dump();
}

// One writer a folder (each rewrites the whole index from what it holds): a second is refused
// while the first lives, and opens once it is gone.
TEST_F(DatasetWriterTest, ASecondWriterOfOneFolderIsRefused) {
  {
    DatasetWriter first(root_.string());
    try {
      DatasetWriter second(root_.string());
      FAIL() << "two writers of one folder";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("another writer"), std::string::npos) << e.what();
    }
    first.Write(MakeClip(0, 1700000000.0), {});
  }
  DatasetWriter later(root_.string());
  EXPECT_EQ(later.size(), 1u);
}

// The parent of the folder is not made (a disk not mounted yet): made, the disk later hid it and
// the first clip after the mount replaced the disk's own index. A folder swapped under an open
// writer (a disk mounted over it) stops the recording instead of replacing that folder's index.
TEST_F(DatasetWriterTest, AMissingParentOrASwappedFolderStopsTheRecording) {
  try {
    DatasetWriter w((root_ / "not-mounted" / "flagreal").string());
    FAIL() << "the parent was made";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist (a disk not mounted yet?)"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(root_ / "not-mounted"));
  fs::create_directories(root_);
  // A trailing slash names the same folder: its "parent" was the folder itself, missing for ever.
  {
    DatasetWriter slash((root_ / "slashed").string() + "//");
    slash.Write(MakeClip(0, 1700000000.0), {});
  }
  EXPECT_EQ(Read(root_ / "slashed" / "index.json")["clips"].size(), 1u);
  const fs::path folder = root_ / "flagreal";
  DatasetWriter w(folder.string());
  w.Write(MakeClip(0, 1700000000.0), {});
  EXPECT_EQ(w.FolderLost(), "");
  // Another folder in its place, holding yesterday's index.
  fs::rename(folder, root_ / "moved");
  EXPECT_NE(w.FolderLost().find("is gone"), std::string::npos) << w.FolderLost();
  fs::create_directories(folder);
  std::ofstream(folder / "index.json") << R"({"format": "clothwind-dataset", "version": 1, "kind": "real", "clips": [{"name": "clip-yesterday"}]})";
  try {
    w.Write(MakeClip(1, 1700000001.2), {});
    FAIL() << "recorded into a swapped folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no longer the one opened"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Read(folder / "index.json")["clips"].size(), 1u);
  EXPECT_EQ(Read(folder / "index.json")["clips"][0]["name"], "clip-yesterday");
  EXPECT_NE(w.FolderLost().find("no longer the one opened"), std::string::npos) << w.FolderLost();
}

TEST(IsMountPointTest, AFolderOnItsParentsDeviceIsNotAndProcIs) {
  const fs::path dir = fs::temp_directory_path() / ("clothwind_mount_point_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  EXPECT_FALSE(IsMountPoint(dir.string()));
  EXPECT_FALSE(IsMountPoint(dir.string() + "/"));
  EXPECT_FALSE(IsMountPoint("/"));
  EXPECT_FALSE(IsMountPoint((dir / "missing").string()));
  fs::remove_all(dir);
  struct stat proc {}, root {};
  if (::stat("/proc", &proc) == 0 && ::stat("/", &root) == 0 && proc.st_dev != root.st_dev) {
    EXPECT_TRUE(IsMountPoint("/proc"));
  }
}

// A writer that died between a clip's rename into place and its index update: the clip is whole
// on disk, and the next writer lists it (no reader saw it before).
TEST_F(DatasetWriterTest, ClipsInPlaceButNotListedAreIndexedOnOpen) {
  {
    DatasetWriter w(root_.string());
    w.Write(MakeClip(0, 1700000000.0), {});
    w.Write(MakeClip(1, 1700000001.2), {});
  }
  nlohmann::json index = Read(root_ / "index.json");
  index["clips"].erase(1);
  std::ofstream(root_ / "index.json") << index.dump();
  fs::create_directories(root_ / "clip-20231114-221320.000-000009");  // no label.json: not a whole clip
  DatasetWriter again(root_.string());
  EXPECT_EQ(again.reindexed(), 1u);
  const nlohmann::json after = Read(root_ / "index.json");
  ASSERT_EQ(after["clips"].size(), 2u);
  EXPECT_EQ(after["clips"][1]["name"], ClipFolderName(1700000001.2));
  EXPECT_EQ(after["clips"][1]["sequence"], 1);
  EXPECT_TRUE(after["clips"][1]["wind_speed"].is_number());
}

// What a writer that died leaves behind is cleared when the folder is opened again; a clip it was
// replacing (renamed aside, the new copy not yet in place) is put back; a live writer's
// temporaries are left alone.
TEST_F(DatasetWriterTest, OpeningClearsADeadWritersLeftovers) {
  {
    DatasetWriter w(root_.string());
    w.Write(MakeClip(0, 1700000000.0), {});
    w.Write(MakeClip(1, 1700000001.2), {});
  }
  const std::string dead = ".tmp-999999999-";  // above any pid_max: no such process
  const std::string clip1 = ClipFolderName(1700000001.2);
  fs::create_directories(root_ / ("." + ClipFolderName(1700000002.4) + dead + "0"));
  std::ofstream(root_ / ("index.json" + dead + "1")) << "{";
  fs::rename(root_ / clip1, root_ / ("." + clip1 + ".old" + dead + "2"));
  const std::string live = "index.json.tmp-" + std::to_string(::getpid()) + "-7";
  std::ofstream(root_ / live) << "{";
  std::ofstream(root_ / ("a" + dead + "3")) << "x";  // a stray short name: threw out_of_range

  DatasetWriter again(root_.string());
  EXPECT_EQ(again.recovered(), 4u);
  EXPECT_FALSE(fs::exists(root_ / ("index.json" + dead + "1")));
  EXPECT_EQ(Read(root_ / clip1 / "label.json")["sequence"], 1);
  EXPECT_EQ(Hidden(), std::set<std::string>{live});  // the live writer's, left alone
  EXPECT_TRUE(fs::exists(root_ / live));
  EXPECT_EQ(again.size(), 2u);
}

}  // namespace
}  // namespace clothwind::sensors
