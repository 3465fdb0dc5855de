// SessionBagWatch on folders laid out as rosbag record leaves them: a bag growing under its .active
// name, one a killed recorder left open, one closed by a rename, other prefixes' bags beside them,
// and a disk whose free space the test sets.
#include "sensors/session_bag_watch.h"

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::sensors {
namespace {
namespace fs = std::filesystem;
using Level = SessionBagReport::Level;

class SessionBagWatchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_session_bag_watch_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A file of `bytes` bytes, last written `age` seconds ago.
  std::string Write(const std::string& name, size_t bytes, double age = 0) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << std::string(bytes, 'x');
    fs::last_write_time(p, fs::file_time_type::clock::now() -
                               std::chrono::duration_cast<fs::file_time_type::duration>(std::chrono::duration<double>(age)));
    return p.string();
  }

  SessionBagWatch Watch(SessionBagWatch::Options o = {}) {
    o.prefix = (dir_ / "session").string();
    return SessionBagWatch(o, [this](const std::string& folder, DiskSpace* space, std::string* error) {
      if (!disk_ok_) {
        *error = "cannot read the free space of " + folder + ": no such disk";
        return false;
      }
      space->available = available_;
      space->capacity = 4 * available_;
      return true;
    });
  }

  fs::path dir_;
  uint64_t available_ = 100000000000;  // 100 GB
  bool disk_ok_ = true;
};

TEST_F(SessionBagWatchTest, WaitsForTheFirstBagThenSaysNoneIsWritten) {
  SessionBagWatch watch = Watch();
  EXPECT_EQ(watch.Poll(0).level, Level::kOk);
  EXPECT_EQ(watch.Poll(14).message, "waiting for the recorder's first bag");
  const SessionBagReport r = watch.Poll(16);
  EXPECT_EQ(r.level, Level::kError);
  EXPECT_EQ(r.message, "no session bag " + (dir_ / "session_").string() +
                           "*.bag.active is being written (for 16 s; is the recorder running?)");
  EXPECT_EQ(r.bag, "");
}

TEST_F(SessionBagWatchTest, ReportsTheBagBeingWrittenItsRateAndTheTimeToFillTheDisk) {
  SessionBagWatch watch = Watch();
  const std::string bag = Write("session_2026-12-07-08-00-00.bag.active", 1000000);
  SessionBagReport r = watch.Poll(0);
  EXPECT_EQ(r.level, Level::kOk);
  EXPECT_EQ(r.bag, bag);
  EXPECT_EQ(r.bag_bytes, 1000000u);
  EXPECT_EQ(r.write_rate, 0);
  Write("session_2026-12-07-08-00-00.bag.active", 3000000);
  r = watch.Poll(1);
  EXPECT_DOUBLE_EQ(r.write_rate, 2e6);
  EXPECT_EQ(r.message, "recording session_2026-12-07-08-00-00.bag.active at 2.0 MB/s");
  EXPECT_DOUBLE_EQ(r.seconds_to_full, 1e11 / 2e6);
  EXPECT_EQ(r.bags_started, 1);
  // Over the window: the slower second counts.
  Write("session_2026-12-07-08-00-00.bag.active", 4000000);
  r = watch.Poll(2);
  EXPECT_DOUBLE_EQ(r.write_rate, 1.5e6);
  EXPECT_EQ(r.seconds_since_growth, 0);
}

TEST_F(SessionBagWatchTest, ABagThatStopsGrowingIsAnError) {
  SessionBagWatch watch = Watch();
  Write("session_2026-12-07-08-00-00.bag.active", 1000);
  EXPECT_EQ(watch.Poll(100).level, Level::kOk);
  EXPECT_EQ(watch.Poll(110).level, Level::kOk);  // 10 s: not yet
  const SessionBagReport r = watch.Poll(111);
  EXPECT_EQ(r.level, Level::kError);
  EXPECT_EQ(r.message, "the session bag " + (dir_ / "session_2026-12-07-08-00-00.bag.active").string() +
                           " has not grown for 11 s (the recorder stopped, or nothing comes to record)");
  EXPECT_DOUBLE_EQ(r.seconds_since_growth, 11);
  Write("session_2026-12-07-08-00-00.bag.active", 2000);
  EXPECT_EQ(watch.Poll(112).level, Level::kOk);
}

TEST_F(SessionBagWatchTest, ARestartedRecordersNewBagIsWatchedAndTheOneLeftOpenIsNamed) {
  SessionBagWatch watch = Watch();
  const std::string first = Write("session_2026-12-07-08-00-00.bag.active", 1000, 2);
  watch.Poll(0);
  // Killed: its bag keeps the .active name; respawned 5 s later, the recorder starts another.
  const std::string second = Write("session_2026-12-07-08-00-07.bag.active", 500);
  SessionBagReport r = watch.Poll(7);
  EXPECT_EQ(r.bag, second);
  EXPECT_EQ(r.bags_started, 2);
  EXPECT_TRUE(r.left_open.empty());  // the first has not stalled for 10 s yet
  Write("session_2026-12-07-08-00-07.bag.active", 900);
  r = watch.Poll(11);
  EXPECT_EQ(r.level, Level::kWarn);
  ASSERT_EQ(r.left_open.size(), 1u);
  EXPECT_EQ(r.left_open[0], first);
  EXPECT_NE(r.message.find("recording session_2026-12-07-08-00-07.bag.active"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("a recorder stopped without closing " + first + " (rosbag reindex it"), std::string::npos)
      << r.message;
  // Closed at the end of the session: renamed to .bag, counted; nothing is written now.
  fs::rename(second, dir_ / "session_2026-12-07-08-00-07.bag");
  r = watch.Poll(12);
  EXPECT_EQ(r.bags_closed, 1);
  EXPECT_EQ(r.bag, first);  // the one left open is all there is, and it does not grow
  EXPECT_EQ(r.level, Level::kError);
}

TEST_F(SessionBagWatchTest, BagsFromBeforeTheWatchAndOtherRecordersAreNotThisSessions) {
  Write("session_2026-12-01-10-00-00.bag.active", 5000, 86400);  // a crash last week
  Write("session_2026-12-01-09-00-00.bag", 5000, 90000);
  Write("session_2026-12-07-09-00-00.bag.active", 5000, -3600);  // dated ahead: the clock stepped back since
  Write("other_2026-12-07-08-00-00.bag.active", 5000);           // another prefix, written now
  Write("session_cam2_2026-12-07-08-00-00.bag.active", 5000);    // another recorder's "session_cam2"
  Write("session-notes_2026-12-07.bag.active", 5000);             // not "<prefix>_"
  Write("session_2026-12-07-08-00-00.txt", 5000);
  SessionBagWatch watch = Watch();
  SessionBagReport r = watch.Poll(0);
  EXPECT_EQ(r.bag, "");  // a leftover passed for the bag being written
  EXPECT_EQ(r.message, "waiting for the recorder's first bag");
  EXPECT_EQ(watch.Poll(16).level, Level::kError);  // the other recorders' bags are not this one's
  const std::string now = Write("session_2026-12-07-08-00-00.bag.active", 100);
  r = watch.Poll(20);
  EXPECT_EQ(r.bag, now);
  EXPECT_EQ(r.level, Level::kOk) << r.message;
  EXPECT_EQ(r.bags_started, 1);
  EXPECT_EQ(r.bags_closed, 0);
  EXPECT_TRUE(r.left_open.empty());
  // Its split parts are its own: rosbag record --split names them <prefix>_<date>_<n>.bag.
  Write("session_2026-12-07-08-00-00_1.bag", 100);
  EXPECT_EQ(watch.Poll(21).bags_closed, 1);
}

TEST_F(SessionBagWatchTest, APrefixEndingInDotBagOrASlashNamesTheBagsRosbagWrites) {
  const std::string bag = Write("session_2026-12-07-08-00-00.bag.active", 100);
  SessionBagWatch::Options o;
  o.prefix = (dir_ / "session.bag").string();  // rosbag drops the ".bag"
  EXPECT_EQ(SessionBagWatch(o).Poll(0).bag, bag);
  const std::string unnamed = Write("_2026-12-07-08-00-00.bag.active", 100);
  o.prefix = dir_.string() + "/";  // rosbag writes <folder>/_<date>.bag
  EXPECT_EQ(SessionBagWatch(o).Poll(0).bag, unnamed);
}

TEST_F(SessionBagWatchTest, LittleFreeSpaceOrADiskFullSoonIsAWarning) {
  SessionBagWatch watch = Watch();
  Write("session_2026-12-07-08-00-00.bag.active", 0);
  available_ = 1500000000;
  SessionBagReport r = watch.Poll(0);
  EXPECT_EQ(r.level, Level::kWarn);
  EXPECT_EQ(r.message, "recording session_2026-12-07-08-00-00.bag.active at 0.0 MB/s; 1500.0 MB free on " +
                           dir_.string());
  // 5 GB free at 10 MB/s: full in 500 s, under the 600 s asked.
  available_ = 5000000000;
  Write("session_2026-12-07-08-00-00.bag.active", 10000000);
  r = watch.Poll(1);
  EXPECT_EQ(r.level, Level::kWarn);
  EXPECT_NE(r.message.find(dir_.string() + " is full in 8 min at 10.0 MB/s"), std::string::npos) << r.message;
  available_ = 7000000000;  // 700 s
  Write("session_2026-12-07-08-00-00.bag.active", 20000000);
  EXPECT_EQ(watch.Poll(2).level, Level::kOk);
  disk_ok_ = false;
  Write("session_2026-12-07-08-00-00.bag.active", 30000000);
  r = watch.Poll(3);
  EXPECT_EQ(r.level, Level::kWarn);
  EXPECT_NE(r.message.find("no such disk"), std::string::npos) << r.message;
}

TEST_F(SessionBagWatchTest, AFolderThatCannotBeReadIsAnErrorAndBadOptionsAreRefused) {
  SessionBagWatch::Options o;
  o.prefix = (dir_ / "missing" / "session").string();
  SessionBagWatch watch(o);
  const SessionBagReport r = watch.Poll(0);
  EXPECT_EQ(r.level, Level::kError);
  EXPECT_EQ(r.message.rfind("cannot read the bag folder " + (dir_ / "missing").string() + ": ", 0), 0u) << r.message;

  o.prefix = "";
  EXPECT_THROW(SessionBagWatch{o}, std::invalid_argument);
  o.prefix = "/data/session";
  o.stall_after = 0;
  EXPECT_THROW(SessionBagWatch{o}, std::invalid_argument);
  o.stall_after = 10;
  o.min_seconds_to_full = std::numeric_limits<double>::infinity();  // it warned whenever a bag grew
  EXPECT_THROW(SessionBagWatch{o}, std::invalid_argument);
}

TEST(StatDiskSpace, ReadsARealFolderAndNamesOneThatIsNot) {
  DiskSpace space;
  std::string error;
  ASSERT_TRUE(StatDiskSpace(fs::temp_directory_path().string(), &space, &error)) << error;
  EXPECT_GT(space.capacity, 0u);
  EXPECT_LE(space.available, space.capacity);
  EXPECT_FALSE(StatDiskSpace("/nonexistent/folder", &space, &error));
  EXPECT_EQ(error, "cannot read the free space of /nonexistent/folder: No such file or directory");
}

}  // namespace
}  // namespace clothwind::sensors
