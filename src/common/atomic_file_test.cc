#include "common/atomic_file.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "common/scoped_file_size_limit.h"

namespace clothwind {
namespace {
namespace fs = std::filesystem;

std::string Read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class AtomicFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_atomic_file_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  size_t Entries() const { return static_cast<size_t>(std::distance(fs::directory_iterator(dir_), {})); }
  fs::path dir_;
};

TEST_F(AtomicFileTest, ReplacesTheContentWhole) {
  const std::string p = (dir_ / "a.json").string();
  WriteFileAtomically(p, std::string("one"));
  WriteFileAtomically(p, std::string("two, longer"));
  EXPECT_EQ(Read(p), "two, longer");
  EXPECT_EQ(Entries(), 1u);  // no temporary left
  try {
    WriteFileAtomically((dir_ / "missing" / "b.json").string(), std::string("x"));
    ADD_FAILURE() << "a file in a missing folder was written";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("missing/b.json"), std::string::npos) << e.what();
  }
  // A folder where the file should go: the rename fails, and the error gives its real reason
  // (it said "Success": the error code was reused by the temporary's removal).
  std::filesystem::create_directories(dir_ / "adir");
  try {
    WriteFileAtomically((dir_ / "adir").string(), std::string("x"));
    ADD_FAILURE() << "a file was written over a folder";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot rename"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("Success"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Entries(), 2u);  // a.json and the folder: no temporary left
}

// A disk that fills up mid-write (RLIMIT_FSIZE stands in: it fails writes for root too): the
// old content stays, the error says why, and the temporary is gone.
TEST_F(AtomicFileTest, AFailedWriteKeepsTheOldContentAndLeavesNoTemporary) {
  const std::string p = (dir_ / "model.json").string();
  WriteFileAtomically(p, std::string("old"));
  std::string message;
  {
    const ScopedFileSizeLimit full_disk(16);
    try {
      WriteFileAtomically(p, std::string(1000, 'x'));
    } catch (const std::exception& e) {
      message = e.what();
    }
  }
  EXPECT_NE(message.find("cannot write"), std::string::npos) << message;
  EXPECT_NE(message.find("too large"), std::string::npos) << message;  // EFBIG's text
  EXPECT_EQ(Read(p), "old");
  EXPECT_EQ(Entries(), 1u);
}

// A model's weights and its model.json as a pair: both in place, or neither changed. A second
// file that cannot take its place (a folder holds its name) puts the first back; the weights
// used to be replaced already, beside an old model.json the loader then refused.
TEST_F(AtomicFileTest, APairIsWrittenWholeOrNotAtAll) {
  const std::string weights = (dir_ / "model.pt").string(), config = (dir_ / "model.json").string();
  WriteFilePairAtomically(weights, "weights 1", config, "config 1");
  EXPECT_EQ(Read(weights), "weights 1");
  EXPECT_EQ(Read(config), "config 1");
  WriteFilePairAtomically(weights, "weights 2", config, "config 2");
  EXPECT_EQ(Read(weights), "weights 2");
  EXPECT_EQ(Read(config), "config 2");
  EXPECT_EQ(Entries(), 2u);  // no temporary or backup left

  const std::string blocked = (dir_ / "blocked.json").string();
  fs::create_directories(fs::path(blocked) / "inside");  // rename() cannot replace a non-empty folder
  std::string message;
  try {
    WriteFilePairAtomically(weights, "weights 3", blocked, "config 3");
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("blocked.json"), std::string::npos) << message;
  EXPECT_EQ(Read(weights), "weights 2");  // put back
  EXPECT_EQ(Entries(), 3u);               // model.pt, model.json and the folder: nothing else

  // A first file that was not there before is removed again.
  const std::string fresh = (dir_ / "fresh.pt").string();
  EXPECT_THROW(WriteFilePairAtomically(fresh, "w", blocked, "c"), std::runtime_error);
  EXPECT_FALSE(fs::exists(fresh));
  EXPECT_EQ(Entries(), 3u);
}

// Where the filesystem has no hard links (vfat, exFAT, some network mounts), the first file's old
// content is kept aside by a durable copy instead, and put back from it when the second fails.
int NoHardLinks(const char*, const char*) {
  errno = EPERM;
  return -1;
}

TEST_F(AtomicFileTest, APairIsWrittenWholeWhereTheFilesystemHasNoHardLinks) {
  const std::string weights = (dir_ / "model.pt").string(), config = (dir_ / "model.json").string();
  WriteFilePairAtomically(weights, "weights 1", config, "config 1", NoHardLinks);
  WriteFilePairAtomically(weights, "weights 2", config, "config 2", NoHardLinks);
  EXPECT_EQ(Read(weights), "weights 2");
  EXPECT_EQ(Read(config), "config 2");
  EXPECT_EQ(Entries(), 2u);  // the copy is gone once the pair is in place

  const std::string blocked = (dir_ / "blocked.json").string();
  fs::create_directories(fs::path(blocked) / "inside");
  EXPECT_THROW(WriteFilePairAtomically(weights, "weights 3", blocked, "config 3", NoHardLinks), std::runtime_error);
  EXPECT_EQ(Read(weights), "weights 2");  // put back from the copy
  EXPECT_EQ(Entries(), 3u);
}

// A training run carries an unchanged best model into its next checkpoint: a hard link where the
// filesystem has them, a whole copy where it has none, and a clear error where neither works.
TEST_F(AtomicFileTest, LinkOrCopyLinksWhereItCanAndCopiesWholeWhereItCannot) {
  const std::string from = (dir_ / "model.pt").string();
  WriteFileAtomically(from, std::string("weights"));
  const std::string linked = (dir_ / "linked.pt").string();
  LinkOrCopyFile(from, linked);
  EXPECT_TRUE(fs::equivalent(from, linked));
  const std::string copied = (dir_ / "copied.pt").string();
  LinkOrCopyFile(from, copied, NoHardLinks);
  EXPECT_FALSE(fs::equivalent(from, copied));
  EXPECT_EQ(Read(copied), "weights");
  EXPECT_EQ(Entries(), 3u);  // no temporary left behind

  try {
    LinkOrCopyFile((dir_ / "missing.pt").string(), (dir_ / "nowhere.pt").string(), NoHardLinks);
    FAIL() << "a missing file was copied";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read " + (dir_ / "missing.pt").string()), std::string::npos) << e.what();
  }
  // A folder is no file to copy: refused naming it, not copied as an empty file (libstdc++'s own
  // "Is a directory" from the read named no file).
  fs::create_directories(dir_ / "folder");
  try {
    LinkOrCopyFile((dir_ / "folder").string(), (dir_ / "folder_copy").string(), NoHardLinks);
    ADD_FAILURE() << "a folder was copied";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read " + (dir_ / "folder").string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir_ / "nowhere.pt"));
  EXPECT_FALSE(fs::exists(dir_ / "folder_copy"));
}

TEST_F(AtomicFileTest, TemporaryNamesDiffer) {
  EXPECT_NE(TemporaryNameFor("x"), TemporaryNameFor("x"));
  EXPECT_EQ(TemporaryNameFor("x").rfind("x.tmp-" + ProcessTag() + "-", 0), 0u);
  EXPECT_EQ(ProcessTag().rfind(std::to_string(::getpid()), 0), 0u);
}

// A child forked after the parent named a temporary names its own by its own pid and start time,
// and the parent's stay the parent's: the tag was made once per process image, so a forked child
// wrote under its parent's tag.
TEST_F(AtomicFileTest, AForkedChildTagsItsTemporariesAsItself) {
  const std::string parent = TemporaryNameFor("x");
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(fds[0]);
    const std::string name = TemporaryNameFor("x");
    const ssize_t n = ::write(fds[1], name.data(), name.size());
    ::_exit(n == static_cast<ssize_t>(name.size()) ? 0 : 1);
  }
  ::close(fds[1]);
  std::string from_child;
  char buf[256];
  for (ssize_t n; (n = ::read(fds[0], buf, sizeof buf)) > 0;) from_child.append(buf, static_cast<size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_EQ(from_child.rfind("x.tmp-" + std::to_string(child), 0), 0u) << from_child;
  EXPECT_EQ(parent.rfind("x.tmp-" + ProcessTag() + "-", 0), 0u) << parent;
  // The child has ended: its names are a stopped process's, the parent's a live one's.
  EXPECT_TRUE(IsTemporaryOfStoppedProcess(from_child)) << from_child;
  EXPECT_FALSE(IsTemporaryOfStoppedProcess(parent)) << parent;
}

TEST_F(AtomicFileTest, ATemporaryIsAStoppedProcessesByItsPidBootAndStartTime) {
  // This process's own names are live; the same pid with another start time (a pid reused after
  // the writer died) or from another boot (a reboot) is a stopped process's, as is a pid that
  // does not run. Names with a pid alone (made before the tag) are judged by the pid.
  const std::string live = TemporaryNameFor(".clip-x");
  EXPECT_FALSE(IsTemporaryOfStoppedProcess(live));
  const std::string pid = std::to_string(::getpid());
  const std::string boot = atomic_file_internal::BootTag();
  const std::string start = atomic_file_internal::ProcessStartTicks(::getpid());
  if (boot.empty() || start.empty()) GTEST_SKIP() << "no /proc here: temporary names carry the pid alone";
  EXPECT_EQ(ProcessTag(), pid + "." + boot + "." + start);
  EXPECT_GT(std::stoll(start), 0);
  size_t at = 0;
  const std::string reused = ".clip-x.tmp-" + pid + "." + boot + "." + std::to_string(std::stoll(start) + 1) + "-0";
  EXPECT_TRUE(IsTemporaryOfStoppedProcess(reused, &at));
  EXPECT_EQ(at, 7u);  // where ".tmp-" starts
  const std::string other_boot = boot == "00000000" ? "11111111" : "00000000";
  EXPECT_TRUE(IsTemporaryOfStoppedProcess(".clip-x.tmp-" + pid + "." + other_boot + "." + start + "-0"));
  EXPECT_TRUE(IsTemporaryOfStoppedProcess("index.json.tmp-999999999." + boot + ".5-0"));
  EXPECT_FALSE(IsTemporaryOfStoppedProcess("index.json.tmp-" + pid + "-3"));
  EXPECT_TRUE(IsTemporaryOfStoppedProcess("index.json.tmp-999999999-3"));
  EXPECT_FALSE(IsTemporaryOfStoppedProcess("index.json"));
  EXPECT_FALSE(IsTemporaryOfStoppedProcess("x.tmp-" + pid + ".garbled")) << "not a name it gives";
}

TEST_F(AtomicFileTest, WritingAPairOrACopyAgainClearsAKilledWritersTemporaries) {
  // A run killed between a pair's two renames (or while copying model.pt) left its temporaries and
  // the first file's backup beside the files for ever; the next write of the pair (or copy) clears
  // them. A live writer's, and other files' temporaries, stay.
  const std::string weights = (dir_ / "m.pt").string(), card = (dir_ / "m.json").string();
  const std::string dead = ".tmp-999999999-0";  // a pid that does not run
  for (const std::string& p : {weights + dead, card + dead, weights + ".old" + dead, (dir_ / "other.pt").string() + dead})
    std::ofstream(p) << "left";
  const std::string live = TemporaryNameFor(weights);
  std::ofstream(live) << "being written";
  WriteFilePairAtomically(weights, "w", card, "c");
  EXPECT_FALSE(fs::exists(weights + dead));
  EXPECT_FALSE(fs::exists(card + dead));
  EXPECT_FALSE(fs::exists(weights + ".old" + dead));
  EXPECT_TRUE(fs::exists(live)) << "a live writer's temporary went";
  EXPECT_TRUE(fs::exists((dir_ / "other.pt").string() + dead)) << "another file's temporary went";
  EXPECT_EQ(Read(weights), "w");
  const std::string copy = (dir_ / "copy.pt").string();
  std::ofstream(copy + dead) << "left";
  CopyFileAtomically(weights, copy);
  EXPECT_FALSE(fs::exists(copy + dead));
  EXPECT_EQ(Read(copy), "w");
}

}  // namespace
}  // namespace clothwind
