#include "sensors/clip_recording.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "common/scoped_file_size_limit.h"

namespace clothwind::sensors {
namespace {
namespace fs = std::filesystem;

class ClipRecordingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    base_ = fs::temp_directory_path() / ("clothwind_clip_recording_test_" + std::to_string(::getpid()));
    fs::remove_all(base_);
    fs::create_directories(base_);
    dir_ = base_ / "clips";
  }
  void TearDown() override { fs::remove_all(base_); }

  ClipRecording::Options Options() {
    ClipRecording::Options o;
    o.dir = dir_.string();
    o.reopen_every = 10;
    o.is_mount_point = [this](const std::string&) { return mounted_; };
    return o;
  }
  LogFn Log() {
    return [this](LogLevel level, const std::string& text) {
      log_ += (level == LogLevel::kError ? "E " : level == LogLevel::kWarn ? "W " : "I ") + text + "\n";
    };
  }

  static LabelledClip MakeClip(uint64_t sequence) {
    LabelledClip c;
    c.clip.sequence = sequence;
    const double t0 = 1700000000.0 + 1.2 * static_cast<double>(sequence);
    for (int i = 0; i < 30; ++i)
      c.clip.frames.push_back({i, t0 + i / 25.0, t0 + i / 25.0, cv::Mat(32, 32, CV_8UC1, cv::Scalar(i * 8))});
    c.label = ComputeWindLabel({{t0, 3.0, 0.0}}, t0 + 1.16, 60.0);
    return c;
  }

  // Waits until the writer's thread has written what is queued.
  static void WaitWritten(const ClipRecording& r) {
    for (int i = 0; i < 500 && r.tally().waiting > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ASSERT_EQ(r.tally().waiting, 0u);
  }

  static size_t Listed(const fs::path& dir) {
    std::ifstream in(dir / "index.json");
    if (!in) return 0;
    return nlohmann::json::parse(in)["clips"].size();
  }

  static std::chrono::steady_clock::time_point Deadline() {
    return std::chrono::steady_clock::now() + std::chrono::seconds(12);
  }

  fs::path base_, dir_;
  bool mounted_ = false;
  std::string log_;
};

TEST_F(ClipRecordingTest, RecordsTheClipsAndTheLastOnesAtShutdown) {
  {
    ClipRecording r(Options(), Log(), 100.0);
    ASSERT_TRUE(r.open()) << r.error();
    for (uint64_t k = 0; k < 3; ++k) r.Record(MakeClip(k), {});
    const auto abandoned = r.Finish({MakeClip(3), MakeClip(4)}, {}, Deadline());
    EXPECT_TRUE(abandoned.empty());
    EXPECT_EQ(r.tally().recorded, 5u);
    EXPECT_EQ(r.tally().not_recorded, 0u);
  }
  EXPECT_EQ(Listed(dir_), 5u);  // every clip listed: none lost to a kill after shutdown began
  EXPECT_NE(log_.find("I recording into " + dir_.string() + " ends: 5 clips written, 0 failed"), std::string::npos)
      << log_;
}

// The last clips at shutdown wait for room in the queue (a queue of one here): a full queue of a
// slow disk dropped them, and no report came after.
TEST_F(ClipRecordingTest, TheLastClipsWaitForRoomInTheQueue) {
  ClipRecording::Options o = Options();
  o.queue = 1;
  {
    ClipRecording r(o, Log(), 100.0);
    std::vector<LabelledClip> waiting;
    for (uint64_t k = 0; k < 8; ++k) waiting.push_back(MakeClip(k));
    EXPECT_TRUE(r.Finish(waiting, {}, Deadline()).empty());
    EXPECT_EQ(r.tally().recorded, 8u);
    EXPECT_EQ(r.tally().not_recorded, 0u);
  }
  EXPECT_EQ(Listed(dir_), 8u);
}

// With no folder open at shutdown the last clips are counted and said, not silently lost.
TEST_F(ClipRecordingTest, TheLastClipsWithNoFolderOpenAreCountedAndSaid) {
  std::ofstream(base_ / "file") << "x";
  ClipRecording::Options o = Options();
  o.dir = (base_ / "file" / "clips").string();
  ClipRecording r(o, Log(), 100.0);
  ASSERT_FALSE(r.open());
  r.Finish({MakeClip(0), MakeClip(1)}, {}, Deadline());
  EXPECT_EQ(r.tally().not_recorded, 2u);
  EXPECT_NE(log_.find("W 2 clips not recorded (no recording folder open: "), std::string::npos) << log_;
}

TEST_F(ClipRecordingTest, NotRecordingCountsNothingAndSaysNothing) {
  ClipRecording::Options o = Options();
  o.dir = "";
  ClipRecording r(o, Log(), 100.0);
  EXPECT_FALSE(r.enabled());
  r.Record(MakeClip(0), {});
  EXPECT_TRUE(r.Poll(200.0, true).empty());
  EXPECT_TRUE(r.Finish({MakeClip(1)}, {}, Deadline()).empty());
  EXPECT_EQ(r.tally().not_recorded, 0u);
  EXPECT_TRUE(log_.empty()) << log_;
}

// A folder that cannot be opened (here: its parent is a file) stops the recording, not the
// clips: counted as not recorded, said once, and tried again every reopen_every seconds.
TEST_F(ClipRecordingTest, AFolderThatCannotOpenIsTriedAgainEveryReopenEvery) {
  std::ofstream(base_ / "file") << "x";
  ClipRecording::Options o = Options();
  dir_ = base_ / "file" / "clips";
  o.dir = dir_.string();
  ClipRecording r(o, Log(), 100.0);
  EXPECT_FALSE(r.open());
  EXPECT_FALSE(r.error().empty());
  r.Record(MakeClip(0), {});
  EXPECT_EQ(r.tally().not_recorded, 1u);
  EXPECT_TRUE(r.Poll(105.0, false).empty());
  EXPECT_TRUE(r.Poll(111.0, false).empty());  // tried again, failing the same way: said once
  EXPECT_EQ(std::count(log_.begin(), log_.end(), '\n'), 1) << log_;
  EXPECT_NE(log_.find("E not recording (publishing clips still; retrying every 10 s)"), std::string::npos) << log_;
  fs::remove(base_ / "file");
  fs::create_directories(base_ / "file");
  r.Poll(115.0, false);
  EXPECT_FALSE(r.open());  // not before reopen_every since the last attempt (111)
  r.Poll(121.0, false);
  EXPECT_TRUE(r.open()) << r.error();
  EXPECT_TRUE(r.error().empty());
  EXPECT_NE(log_.find("I recording works again"), std::string::npos) << log_;
}

// A folder lost (a disk unplugged) is closed off the caller's thread and reopened only once it is
// a folder again, never made again; the tally runs on across the two.
TEST_F(ClipRecordingTest, ALostFolderIsReopenedOnceItIsBackAndTheTallyRunsOn) {
  ClipRecording r(Options(), Log(), 100.0);
  ASSERT_TRUE(r.open());
  r.Record(MakeClip(0), {});
  r.Record(MakeClip(1), {});
  WaitWritten(r);
  fs::rename(dir_, base_ / "unplugged");
  const auto problems = r.Poll(101.0, false);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("reopening it every 10 s once it is there"), std::string::npos) << problems[0];
  EXPECT_FALSE(r.open());
  EXPECT_TRUE(r.Poll(102.0, false).empty());  // said once
  r.Record(MakeClip(2), {});                   // no folder: not recorded
  double now = 112.0;
  for (int i = 0; i < 200 && r.error().find("is gone; waiting") == std::string::npos; ++i, now += 10) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the lost writer closing
    r.Poll(now, false);
  }
  EXPECT_FALSE(r.open());
  EXPECT_FALSE(fs::exists(dir_));  // not made again: clips never land where the disk is not
  EXPECT_NE(r.error().find("is gone; waiting for it to come back"), std::string::npos) << r.error();
  fs::create_directories(dir_);
  r.Poll(now + 10, false);
  ASSERT_TRUE(r.open()) << r.error();
  r.Record(MakeClip(3), {});
  r.Finish({}, {}, Deadline());
  EXPECT_EQ(r.tally().recorded, 3u);
  EXPECT_EQ(r.tally().not_recorded, 1u);
  // The two clips written before the disk went are on it (its index lists them when the folder is
  // next opened: the closing writer could not reach it), the one after it came back in its index.
  size_t on_unplugged = 0;
  for (const auto& e : fs::directory_iterator(base_ / "unplugged")) on_unplugged += e.path().filename().string().rfind("clip-", 0) == 0;
  EXPECT_EQ(on_unplugged, 2u);
  EXPECT_EQ(Listed(dir_), 1u);
}

// Lost twice (a disk replugged twice): the first lost writer's closing thread is joined before the
// second's starts (a joinable std::thread replaced ends the process).
TEST_F(ClipRecordingTest, AFolderLostTwiceIsReopenedTwice) {
  ClipRecording r(Options(), Log(), 100.0);
  double now = 100.0;
  for (int loss = 0; loss < 2; ++loss) {
    ASSERT_TRUE(r.open()) << loss;
    r.Record(MakeClip(loss), {});
    WaitWritten(r);
    fs::rename(dir_, base_ / ("unplugged" + std::to_string(loss)));
    now += 1;
    ASSERT_EQ(r.Poll(now, false).size(), 1u) << loss;
    fs::create_directories(dir_);
    for (int i = 0; i < 200 && !r.open(); ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the lost writer closing
      now += 10;
      r.Poll(now, false);
    }
  }
  ASSERT_TRUE(r.open()) << r.error();
  EXPECT_EQ(r.tally().recorded, 2u);
}

// The clips queued when the folder goes (the one being written among them) are counted as not
// recorded, once (they fail in the folder that went, which the lost writer's closing does not
// count again), and the log says so apart from the clips that found no folder open. Their frames
// are noise, slow to encode, so the loss finds them still queued.
TEST_F(ClipRecordingTest, TheClipsQueuedWhenTheFolderGoesAreCountedOnceAsNotRecorded) {
  ClipRecording r(Options(), Log(), 100.0);
  ASSERT_TRUE(r.open());
  cv::Mat noise(1024, 1024, CV_8UC1);
  cv::randu(noise, 0, 256);
  constexpr int kClips = 3;
  for (uint64_t k = 0; k < kClips; ++k) {
    LabelledClip c = MakeClip(k);
    for (auto& f : c.clip.frames) f.image = noise;  // shared, not copied
    r.Record(c, {});
  }
  ASSERT_GE(r.tally().waiting, 2u) << "the writer took the clips before the test could lose the folder";
  fs::rename(dir_, base_ / "unplugged");
  ASSERT_EQ(r.Poll(101.0, false).size(), 1u);
  double now = 111.0;
  for (int i = 0; i < 500 && r.error().find("is gone; waiting") == std::string::npos; ++i, now += 10) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the lost writer closing
    r.Poll(now, false);
  }
  ASSERT_NE(r.error().find("is gone; waiting"), std::string::npos) << r.error();
  r.Record(MakeClip(kClips), {});  // no folder open
  size_t on_unplugged = 0;
  for (const auto& e : fs::directory_iterator(base_ / "unplugged"))
    on_unplugged += e.path().filename().string().rfind("clip-", 0) == 0;
  const ClipRecording::Tally t = r.tally();
  EXPECT_EQ(t.recorded, on_unplugged) << "the clips on the unplugged disk are the ones counted recorded";
  EXPECT_EQ(t.recorded + t.not_recorded, static_cast<uint64_t>(kClips + 1))
      << "recorded " << t.recorded << ", not recorded " << t.not_recorded;
  r.Finish({}, {}, Deadline());
  EXPECT_NE(log_.find("1 clips not recorded (no recording folder open"), std::string::npos) << log_;
  EXPECT_NE(log_.find(" queued when a folder was lost"), std::string::npos) << log_;
}

// A lost folder's writer can hang in its last write (a yanked disk's): it is closed off the
// caller's thread, so Poll returns at once, and the folder, back already, is not reopened until
// that writer has closed (two writers in one path would each rewrite the index). The hang is a
// FIFO where the writer reads an earlier clip's label.json, which blocks until the test opens it.
TEST_F(ClipRecordingTest, ALostWriterHangingInAWriteHoldsNeitherPollNorAReopenedFolder) {
  ClipRecording r(Options(), Log(), 100.0);
  ASSERT_TRUE(r.open());
  const LabelledClip clip = MakeClip(0);
  // Made after opening: the opening reads the label.json of every clip folder the index lacks.
  const fs::path held = dir_ / ClipFolderName(clip.clip.frames.front().stamp);
  fs::create_directories(held);
  ASSERT_EQ(::mkfifo((held / "label.json").c_str(), 0600), 0) << std::strerror(errno);
  // Lets the hanging read end (EOF), wherever the FIFO is by then and whatever the test's outcome
  // (the writers' threads are joined at the end).
  auto release = [this, name = held.filename()] {
    for (const fs::path& fifo : {base_ / "unplugged" / name / "label.json", dir_ / name / "label.json"}) {
      const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);  // fails (ENXIO) with no reader
      if (fd >= 0) return ::close(fd) == 0;
    }
    return false;
  };
  struct Releaser {
    std::function<bool()> release;
    ~Releaser() { release(); }
  } releaser{release};
  r.Record(clip, {});
  // The writer's thread blocks opening the FIFO (the kernel's wait_for_partner): before that, a
  // loss would fail its write at once, and there would be no hang to test.
  auto a_thread_waits_on_a_fifo = [] {
    for (const auto& task : fs::directory_iterator("/proc/self/task")) {
      std::ifstream wchan(task.path() / "wchan");
      std::string where;
      if (wchan >> where && where == "wait_for_partner") return true;
    }
    return false;
  };
  for (int i = 0; i < 500 && !a_thread_waits_on_a_fifo(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_TRUE(a_thread_waits_on_a_fifo()) << "the writer did not reach the FIFO";
  ASSERT_EQ(r.tally().waiting, 1u);
  fs::rename(dir_, base_ / "unplugged");
  auto poll = std::async(std::launch::async, [&r] { return r.Poll(101.0, false); });
  if (poll.wait_for(std::chrono::seconds(10)) != std::future_status::ready) {
    release();
    FAIL() << "Poll waited for the lost writer's hanging write";
  }
  ASSERT_EQ(poll.get().size(), 1u);
  EXPECT_FALSE(r.open());
  fs::create_directories(dir_);  // the disk back, while the lost writer still hangs
  r.Poll(111.0, false);
  r.Poll(121.0, false);
  EXPECT_FALSE(r.open()) << "reopened while the lost writer was still closing";
  ASSERT_TRUE(release()) << "the lost writer was not reading the FIFO";
  double now = 131.0;
  for (int i = 0; i < 500 && !r.open(); ++i, now += 10) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the lost writer closing
    r.Poll(now, false);
  }
  EXPECT_TRUE(r.open()) << r.error();
  const ClipRecording::Tally t = r.tally();
  EXPECT_EQ(t.recorded + t.not_recorded, 1u);
}

// A disk mounted at the folder: once lost, its bare mount point (an fstab entry) is a folder but
// not the disk, and the recording waits for the disk.
TEST_F(ClipRecordingTest, ABareMountPointIsNotTheDisk) {
  mounted_ = true;
  ClipRecording r(Options(), Log(), 100.0);
  ASSERT_TRUE(r.open());
  fs::rename(dir_, base_ / "unplugged");
  fs::create_directories(dir_);  // the bare mount point
  mounted_ = false;
  r.Poll(101.0, false);
  double now = 111.0;
  for (int i = 0; i < 200 && r.error().find("is not there") == std::string::npos; ++i, now += 10) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));  // the lost writer closing
    r.Poll(now, false);
  }
  EXPECT_FALSE(r.open());
  EXPECT_NE(r.error().find("is not there; waiting for it to come back"), std::string::npos) << r.error();
  mounted_ = true;  // the disk mounted again
  r.Poll(now + 10, false);
  EXPECT_TRUE(r.open()) << r.error();
}

// A disk that refuses the writes (full: here a file size limit, which binds root too, where
// permissions do not): the failure is said by the next Poll with the writer's error, once, the
// clip counted as not recorded, and the folder stays open for the next clip.
TEST_F(ClipRecordingTest, AFailedWriteIsSaidOnceAndCounted) {
  ClipRecording r(Options(), Log(), 100.0);
  ASSERT_TRUE(r.open());
  {
    ScopedFileSizeLimit full(64);  // less than one JPEG frame
    r.Record(MakeClip(0), {});
    WaitWritten(r);
  }
  const auto problems = r.Poll(101.0, false);
  ASSERT_FALSE(problems.empty());
  EXPECT_EQ(problems[0].rfind("recording failed: ", 0), 0u) << problems[0];
  EXPECT_TRUE(r.Poll(102.0, false).empty());
  EXPECT_EQ(r.tally().not_recorded, 1u);
  EXPECT_TRUE(r.open());
  r.Record(MakeClip(1), {});
  WaitWritten(r);
  EXPECT_TRUE(r.Poll(103.0, false).empty());
  EXPECT_EQ(r.tally().recorded, 1u);
}

// A clip recorded whose index update failed (a folder where index.json goes) is recorded, not
// "not recorded", and the next Poll says the problem, once.
TEST_F(ClipRecordingTest, AClipRecordedWithAProblemIsCountedRecordedAndTheProblemSaid) {
  ClipRecording::Options o = Options();
  o.index_interval = 0;  // every clip rewrites the index
  ClipRecording r(o, Log(), 100.0);
  ASSERT_TRUE(r.open());
  fs::remove(dir_ / "index.json");
  fs::create_directories(dir_ / "index.json" / "blocker");
  r.Record(MakeClip(0), {});
  WaitWritten(r);
  const auto problems = r.Poll(101.0, false);
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("recorded, but"), std::string::npos) << problems[0];
  EXPECT_TRUE(r.Poll(102.0, false).empty());
  EXPECT_EQ(r.tally().recorded, 1u);
  EXPECT_EQ(r.tally().not_recorded, 0u);
  fs::remove_all(dir_ / "index.json");
}

// Input stopped (a replay ended): the clips written since the last index rewrite are listed now,
// not after index_interval.
TEST_F(ClipRecordingTest, InputStoppingListsTheClipsWritten) {
  ClipRecording::Options o = Options();
  o.index_interval = 3600;
  ClipRecording r(o, Log(), 100.0);
  ASSERT_TRUE(r.open());
  for (uint64_t k = 0; k < 3; ++k) r.Record(MakeClip(k), {});
  WaitWritten(r);
  ASSERT_GT(r.tally().unlisted, 0u);
  r.Poll(101.0, /*input_idle=*/true);
  for (int i = 0; i < 500 && r.tally().unlisted > 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(r.tally().unlisted, 0u);
  EXPECT_EQ(Listed(dir_), 3u);
}

TEST(ClipRecordingNamesTest, JoinNamesShortensLongLists) {
  EXPECT_EQ(ClipRecording::JoinNames({"a", "b", "c"}), "a, b, c");
  EXPECT_EQ(ClipRecording::JoinNames({"1", "2", "3", "4", "5", "6", "7", "8", "9"}), "1, 2, 3, 4, ... (4 more), 9");
}

}  // namespace
}  // namespace clothwind::sensors
