// An interrupted child removes the temporaries it registered and dies of the signal; one whose
// registration ended keeps its file.
#include "remove_on_interrupt.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {
namespace fs = std::filesystem;

class RemoveOnInterruptTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_remove_on_interrupt_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  // Forks a child that registers `registered` (a file it writes), writes `kept` after its
  // registration ended, and raises `sig`. Returns the child's wait status.
  int RunChild(int sig, const fs::path& registered, const fs::path& kept) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      {
        RemoveOnInterrupt done(kept.string());
        std::ofstream(kept) << "kept";
      }
      RemoveOnInterrupt remove(registered.string());
      std::ofstream(registered) << "half a bag";
      ::raise(sig);
      ::_exit(0);  // not reached
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
  }

  fs::path dir_;
};

TEST_F(RemoveOnInterruptTest, AnInterruptRemovesTheRegisteredTemporaryAndEndsTheProcessByTheSignal) {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    const fs::path tmp = dir_ / ("session.bag.tmp-" + std::to_string(sig)), kept = dir_ / ("done-" + std::to_string(sig));
    const int status = RunChild(sig, tmp, kept);
    ASSERT_TRUE(WIFSIGNALED(status)) << sig;
    EXPECT_EQ(WTERMSIG(status), sig);
    EXPECT_FALSE(fs::exists(tmp)) << sig;
    EXPECT_TRUE(fs::exists(kept)) << sig;
  }
}

TEST_F(RemoveOnInterruptTest, AnIgnoredSignalStaysIgnored) {
  // As under nohup: SIGHUP ignored before the registration; raised, the child lives on.
  const fs::path tmp = dir_ / "session.bag.tmp-nohup";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGHUP, SIG_IGN);
    RemoveOnInterrupt remove(tmp.string());
    std::ofstream(tmp) << "half a bag";
    ::raise(SIGHUP);
    ::_exit(7);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 7);
  EXPECT_TRUE(fs::exists(tmp));
}

TEST_F(RemoveOnInterruptTest, WithoutAnInterruptTheFileStays) {
  const fs::path tmp = dir_ / "session.bag.tmp-1";
  {
    RemoveOnInterrupt remove(tmp.string());
    std::ofstream(tmp) << "whole";
  }
  EXPECT_TRUE(fs::exists(tmp));
}

}  // namespace
}  // namespace clothwind::tools
