#include "sensors/async_dataset_writer.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <chrono>
#include <fstream>
#include <thread>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {
namespace fs = std::filesystem;

class AsyncDatasetWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("clothwind_async_writer_test_" + std::to_string(::getpid()));
    fs::remove_all(root_);
  }
  void TearDown() override { fs::remove_all(root_); }

  static LabelledClip MakeClip(uint64_t sequence, int frames = 30) {
    LabelledClip c;
    c.clip.sequence = sequence;
    const double t0 = 1700000000.0 + 1.2 * static_cast<double>(sequence);
    for (int i = 0; i < frames; ++i)
      c.clip.frames.push_back({i, t0 + i / 25.0, t0 + i / 25.0, cv::Mat(64, 64, CV_8UC1, cv::Scalar(i * 8))});
    c.label = ComputeWindLabel({{t0, 3.0, 0.0}}, t0 + 1.16, 60.0);
    return c;
  }

  size_t IndexSize() const {
    if (!fs::exists(root_ / "index.json")) return 0;  // no clip written yet
    std::ifstream in(root_ / "index.json");
    return nlohmann::json::parse(in)["clips"].size();
  }

  fs::path root_;
};

TEST_F(AsyncDatasetWriterTest, RecordsEveryQueuedClip) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()), 16);
  for (uint64_t k = 0; k < 6; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
  w.Drain();
  const auto s = w.stats();
  EXPECT_EQ(s.written, 6u);
  EXPECT_EQ(s.failed + s.dropped + s.queued, 0u);
  EXPECT_GT(s.max_write_s, 0.0);
  EXPECT_EQ(IndexSize(), 6u);
  for (uint64_t k = 0; k < 6; ++k)
    EXPECT_TRUE(fs::exists(root_ / ClipFolderName(1700000000.0 + 1.2 * static_cast<double>(k)) / "029.jpg"));
}

// A disk slower than the clips: the queue bounds the memory held, the rest is counted, and
// nothing blocks the caller. (50 clips are queued in microseconds; each write takes milliseconds.)
TEST_F(AsyncDatasetWriterTest, FullQueueDropsAndCounts) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()), 1);
  int accepted = 0;
  for (uint64_t k = 0; k < 50; ++k) accepted += w.Enqueue(MakeClip(k), {}) ? 1 : 0;
  w.Drain();
  const auto s = w.stats();
  EXPECT_EQ(s.written, static_cast<uint64_t>(accepted));
  EXPECT_EQ(s.written + s.dropped, 50u);
  EXPECT_GT(s.dropped, 0u);
  EXPECT_EQ(IndexSize(), s.written);
}

TEST_F(AsyncDatasetWriterTest, WaitingForRoomDropsNothing) {
  // The clips flushed at shutdown: a full queue dropped them, and no report came after.
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()), 1);
  for (uint64_t k = 0; k < 50; ++k) EXPECT_TRUE(w.Enqueue(MakeClip(k), {}, /*wait_for_room=*/true)) << k;
  w.Drain();
  const auto s = w.stats();
  EXPECT_EQ(s.written, 50u);
  EXPECT_EQ(s.dropped, 0u);
  EXPECT_EQ(IndexSize(), 50u);
}

TEST_F(AsyncDatasetWriterTest, FailedWriteIsCountedWithItsReason) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()));
  ASSERT_TRUE(w.Enqueue(MakeClip(0, 0), {}));  // no frames: DatasetWriter refuses it
  ASSERT_TRUE(w.Enqueue(MakeClip(1), {}));
  w.Drain();
  const auto s = w.stats();
  EXPECT_EQ(s.failed, 1u);
  EXPECT_EQ(s.written, 1u);
  EXPECT_NE(s.last_error.find("empty clip"), std::string::npos) << s.last_error;
}

// A clip in place whose index update failed (a folder stands where index.json goes) is written,
// not failed: counted as a failed write, a recording's tally called a clip on disk not recorded.
// The problem is counted and said apart.
TEST_F(AsyncDatasetWriterTest, AClipRecordedWhoseIndexUpdateFailedIsWrittenWithItsProblem) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()));
  fs::remove(root_ / "index.json");
  fs::create_directories(root_ / "index.json" / "blocker");
  ASSERT_TRUE(w.Enqueue(MakeClip(0), {}));
  w.Drain();
  const auto s = w.stats();
  EXPECT_EQ(s.written, 1u);
  EXPECT_EQ(s.failed, 0u);
  EXPECT_EQ(s.problems, 1u);
  EXPECT_NE(s.last_problem.find("recorded, but"), std::string::npos) << s.last_problem;
  EXPECT_NE(s.last_problem.find("index.json not updated"), std::string::npos) << s.last_problem;
  fs::remove_all(root_ / "index.json");
}

TEST_F(AsyncDatasetWriterTest, AnIdleWriterListsItsUnlistedClipsOnceTheIndexIntervalPasses) {
  // Interval 5 s: two clips queued at once, the second is written within the interval of the
  // first's index rewrite, so it waits unlisted; with no clip after it (a replay that ended) the
  // idle thread rewrites the index once the interval has passed, without Drain. (The count of
  // unlisted clips is updated just after the new index is in place: both are waited for.)
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 5.0), 16);
  ASSERT_TRUE(w.Enqueue(MakeClip(0), {}));
  ASSERT_TRUE(w.Enqueue(MakeClip(1), {}));
  for (int i = 0; i < 2000 && w.stats().written < 2; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(w.stats().written, 2u);
  EXPECT_EQ(IndexSize(), 1u);
  EXPECT_EQ(w.stats().unlisted, 1u);
  for (int i = 0; i < 3000 && (IndexSize() < 2 || w.stats().unlisted > 0); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(IndexSize(), 2u);
  EXPECT_EQ(w.stats().unlisted, 0u);
  EXPECT_EQ(w.stats().index_error, "");
}

TEST_F(AsyncDatasetWriterTest, DrainListsEveryClipWhateverTheIndexInterval) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 3600.0), 16);
  for (uint64_t k = 0; k < 5; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
  w.Drain();
  EXPECT_EQ(w.stats().written, 5u);
  EXPECT_EQ(IndexSize(), 5u);
  EXPECT_EQ(w.stats().unlisted, 0u);
  ASSERT_TRUE(w.Enqueue(MakeClip(5), {}));
  w.Drain();
  EXPECT_EQ(IndexSize(), 6u);
  // RequestIndexFlush: the same without waiting.
  for (uint64_t k = 6; k < 9; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
  w.RequestIndexFlush();
  for (int i = 0; i < 1000 && IndexSize() < 9; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(IndexSize(), 9u);
  EXPECT_EQ(w.stats().written, 9u);
}

TEST_F(AsyncDatasetWriterTest, DrainListsAClipWrittenWhileAnIndexRewriteRan) {
  // A flush asked for while an index rewrite runs (the node's RequestIndexFlush, then a Drain)
  // must get a rewrite of its own: the request used to be cleared when the running rewrite
  // ended, and Drain returned with the clip written meanwhile unlisted. Repeated, since the
  // window is the length of one rewrite.
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 86400.0), 16);
  for (uint64_t k = 0; k < 100; ++k) {
    w.RequestIndexFlush();
    ASSERT_TRUE(w.Enqueue(MakeClip(k, 2), {}));
    w.Drain();
    ASSERT_EQ(IndexSize(), k + 1) << "clip " << k;
  }
}

TEST_F(AsyncDatasetWriterTest, DrainByRecordsAndListsEverythingBeforeItsDeadline) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 3600.0), 16);
  for (uint64_t k = 0; k < 5; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
  std::vector<std::string> abandoned;
  EXPECT_TRUE(w.DrainBy(std::chrono::steady_clock::now() + std::chrono::seconds(60), &abandoned));
  EXPECT_TRUE(abandoned.empty());
  EXPECT_EQ(w.stats().written, 5u);
  EXPECT_EQ(w.stats().abandoned, 0u);
  EXPECT_EQ(IndexSize(), 5u);
}

// A shutdown whose deadline comes before the disk is done: the clips still queued are given up
// and named (roslaunch's SIGKILL would take them anyway, unnamed), and every clip that did land
// is listed: the clips written, the given up, and the folders on disk add up.
TEST_F(AsyncDatasetWriterTest, DrainByGivesUpWhatIsQueuedAtItsDeadlineAndNamesIt) {
  std::vector<std::string> abandoned;
  {
    AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 3600.0), 16);
    // 16 clips queue in microseconds; each takes milliseconds (30 fsync'ed JPEGs).
    for (uint64_t k = 0; k < 16; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
    EXPECT_FALSE(w.DrainBy(std::chrono::steady_clock::now(), &abandoned));
    EXPECT_EQ(w.stats().abandoned, abandoned.size());
  }
  ASSERT_FALSE(abandoned.empty());
  size_t on_disk = 0;
  for (uint64_t k = 0; k < 16; ++k) {
    const std::string name = ClipFolderName(1700000000.0 + 1.2 * static_cast<double>(k));
    const bool given_up = std::find(abandoned.begin(), abandoned.end(), name) != abandoned.end();
    EXPECT_NE(fs::exists(root_ / name), given_up) << name;
    on_disk += given_up ? 0 : 1;
  }
  EXPECT_EQ(on_disk + abandoned.size(), 16u);
  EXPECT_EQ(IndexSize(), on_disk);
}

// A clip is started at shutdown only if it would land by the deadline, at the last write's pace:
// one started just before the deadline ran a whole write past it (on a slow card, past
// roslaunch's SIGKILL). Here the deadline leaves time for the clip being written and not for a
// second: the other two are named, where the second was started and written after the deadline
// (and one named at most).
// (The pace is the fastest of three writes, so a write slower than usual under load still reads
// as too slow to fit.)
TEST_F(AsyncDatasetWriterTest, DrainByStartsNoClipThatWouldLandAfterItsDeadline) {
  std::vector<std::string> abandoned;
  double pace = 1e9;
  {
    AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 3600.0), 16);
    for (uint64_t k = 0; k < 3; ++k) {
      ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
      w.Drain();
      pace = std::min(pace, w.stats().last_write_s);
    }
    ASSERT_GT(pace, 0.0);
    for (uint64_t k = 3; k < 6; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(1.2 * pace));
    EXPECT_FALSE(w.DrainBy(deadline, &abandoned));
    // Given up, it is over: a clip after it is refused and counted (it waited in the queue
    // unwritten and uncounted), and Drain returns.
    const uint64_t dropped = w.stats().dropped;
    EXPECT_FALSE(w.Enqueue(MakeClip(9), {}));
    EXPECT_EQ(w.stats().dropped, dropped + 1);
    w.Drain();
  }
  // Two, or all three when the writer had not yet taken the first when DrainBy came (under load,
  // its index rewrite then leaves too little time for one).
  EXPECT_GE(abandoned.size(), 2u) << "pace " << pace << " s a clip";
  EXPECT_EQ(IndexSize(), 6u - abandoned.size());
}

// A shutdown drain killed mid-way (roslaunch's SIGKILL 17 s after Ctrl-C, a slow card): every
// clip folder on disk is listed, bar the one whose folder landed just before the kill. Before
// DrainBy listed each clip, the index kept only what its interval had let through (here the
// first clip) and the rest vanished from train and eval, which read the index only.
TEST_F(AsyncDatasetWriterTest, ADrainKilledMidwayLeavesEveryClipOnDiskListed) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the recording process: no gtest assertions here, only its exit or kill
    AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 3600.0), 64);
    for (uint64_t k = 0; k < 60; ++k) w.Enqueue(MakeClip(k), {});
    w.DrainBy(std::chrono::steady_clock::now() + std::chrono::seconds(120), nullptr);
    ::_exit(0);
  }
  auto clips_on_disk = [this] {
    size_t n = 0;
    std::error_code ec;
    for (fs::directory_iterator it(root_, ec), end; !ec && it != end; it.increment(ec))
      n += it->path().filename().string().rfind("clip-", 0) == 0 ? 1 : 0;
    return n;
  };
  for (int i = 0; i < 4000 && clips_on_disk() < 8; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the drain ended before the kill: too few clips to catch it mid-way";
  const size_t on_disk = clips_on_disk();
  ASSERT_GE(on_disk, 8u);
  EXPECT_GE(IndexSize() + 1, on_disk);
}

TEST_F(AsyncDatasetWriterTest, EnqueueGivesUpWaitingForRoomAtItsDeadline) {
  AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()), 1);
  int accepted = 0;
  const auto past = std::chrono::steady_clock::now();
  for (uint64_t k = 0; k < 20; ++k) accepted += w.Enqueue(MakeClip(k), {}, past) ? 1 : 0;
  w.Drain();
  EXPECT_LT(accepted, 20);
  EXPECT_EQ(w.stats().abandoned, 20u - static_cast<uint64_t>(accepted));
  EXPECT_EQ(w.stats().dropped, 0u);  // counted once, as given up
  EXPECT_EQ(w.stats().written, static_cast<uint64_t>(accepted));
}

TEST_F(AsyncDatasetWriterTest, DestructorRecordsWhatIsQueued) {
  {
    AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string()), 16);
    for (uint64_t k = 0; k < 8; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
  }
  EXPECT_EQ(IndexSize(), 8u);
  {  // and lists them with an index interval too
    AsyncDatasetWriter w(std::make_unique<DatasetWriter>(root_.string(), 95, 3600.0), 16);
    for (uint64_t k = 8; k < 12; ++k) ASSERT_TRUE(w.Enqueue(MakeClip(k), {}));
  }
  EXPECT_EQ(IndexSize(), 12u);
}

}  // namespace
}  // namespace clothwind::sensors
