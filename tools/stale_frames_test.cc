#include "stale_frames.h"

#include <unistd.h>

#include <fstream>

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {
namespace fs = std::filesystem;

TEST(StaleFramesTest, FrameNumberReadsOnlyItsOwnPattern) {
  EXPECT_EQ(FrameNumber("0012_00.obj", 4, "_00.obj"), 12);
  EXPECT_EQ(FrameNumber("0012_01.obj", 4, "_00.obj"), std::nullopt);  // another cloth
  EXPECT_EQ(FrameNumber("012_00.obj", 4, "_00.obj"), std::nullopt);
  EXPECT_EQ(FrameNumber("00a2_00.obj", 4, "_00.obj"), std::nullopt);
  EXPECT_EQ(FrameNumber("007.jpg", 3, ".jpg"), 7);
  EXPECT_EQ(FrameNumber("zeta.json", 3, ".jpg"), std::nullopt);
  // Past the width printf pads to, as frames 1000 and 10000 are named (they were missed).
  EXPECT_EQ(FrameNumber("1000.png", 3, ".png"), 1000);
  EXPECT_EQ(FrameNumber("12345_00.obj", 4, "_00.obj"), 12345);
  EXPECT_EQ(FrameNumber("0012.jpg", 3, ".jpg"), std::nullopt);  // no "%03d" name
  EXPECT_EQ(FrameNumber(".jpg", 3, ".jpg"), std::nullopt);
}

TEST(StaleFramesTest, ObjFrameAndClothReadArcSimNames) {
  EXPECT_EQ(ObjFrameAndCloth("0012_01.obj"), std::make_pair(12, 1));
  EXPECT_EQ(ObjFrameAndCloth("0000_00.obj"), std::make_pair(0, 0));
  EXPECT_EQ(ObjFrameAndCloth("12345_100.obj"), std::make_pair(12345, 100));
  EXPECT_EQ(ObjFrameAndCloth("012_00.obj"), std::nullopt);
  EXPECT_EQ(ObjFrameAndCloth("0012_1.obj"), std::nullopt);
  EXPECT_EQ(ObjFrameAndCloth("0012_01.obj.bak"), std::nullopt);
  EXPECT_EQ(ObjFrameAndCloth("flag.obj"), std::nullopt);
  EXPECT_EQ(ObjFrameAndCloth("a_0012_01.obj"), std::nullopt);
  EXPECT_EQ(ObjFrameAndCloth(".obj"), std::nullopt);
}

TEST(StaleFramesTest, IsSimulateTrajectoryReadsItsNames) {
  for (const char* yes : {"trajectory.cwtraj", "trajectory_1.cwtraj", "trajectory_12.cwtraj"})
    EXPECT_TRUE(IsSimulateTrajectory(yes)) << yes;
  for (const char* no : {"trajectory_0.cwtraj", "trajectory_01.cwtraj", "trajectory_.cwtraj", "trajectory_a.cwtraj",
                         "other.cwtraj", "trajectory.cwtraj.tmp", "summary.json"})
    EXPECT_FALSE(IsSimulateTrajectory(no)) << no;
}

// A shorter rerun: frames past its count go, its own frames and other files stay.
TEST(StaleFramesTest, RemovesOnlyTheFramesBeyondTheNewRun) {
  const fs::path dir = fs::temp_directory_path() / ("clothwind_stale_frames_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* name : {"000.jpg", "001.jpg", "002.jpg", "003.jpg", "zeta.json", "0003_00.obj"})
    std::ofstream(dir / name) << "x";
  const int removed = RemoveStaleFrames(dir, [](const std::string& name) {
    const auto n = FrameNumber(name, 3, ".jpg");
    return n && *n >= 2;
  });
  EXPECT_EQ(removed, 2);
  for (const char* kept : {"000.jpg", "001.jpg", "zeta.json", "0003_00.obj"}) EXPECT_TRUE(fs::exists(dir / kept)) << kept;
  for (const char* gone : {"002.jpg", "003.jpg"}) EXPECT_FALSE(fs::exists(dir / gone)) << gone;
  EXPECT_EQ(RemoveStaleFrames(dir / "missing", [](const std::string&) { return true; }), 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::tools
