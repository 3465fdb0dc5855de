#include "data/paths.h"

#include <unistd.h>

#include <gtest/gtest.h>

namespace clothwind::data {
namespace {
namespace fs = std::filesystem;

// A fake file tree: a source checkout and an install prefix, each with a config folder.
class ConfigDirTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("clothwind_paths_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "src" / "config");
    fs::create_directories(root_ / "prefix" / "share" / "clothwind" / "config");
    fs::create_directories(root_ / "prefix" / "bin");
    fs::create_directories(root_ / "prefix" / "lib" / "clothwind");
  }
  void TearDown() override { fs::remove_all(root_); }
  std::string Installed() const { return (root_ / "prefix" / "share" / "clothwind" / "config").string(); }
  fs::path root_;
};

TEST_F(ConfigDirTest, SourceDirVariableComesFirst) {
  EXPECT_EQ(ConfigDirFor((root_ / "src").string(), root_ / "prefix" / "bin" / "clothwind", "/built/config"),
            (root_ / "src" / "config").string());
}

TEST_F(ConfigDirTest, AnInstalledProgramFindsItsPrefixsShareFolder) {
  // The CLI (bin/) and the nodes (lib/clothwind/) of a moved install space, no variable set.
  EXPECT_EQ(ConfigDirFor("", root_ / "prefix" / "bin" / "clothwind", "/built/config"), Installed());
  EXPECT_EQ(ConfigDirFor("", root_ / "prefix" / "lib" / "clothwind" / "sdn_node", "/built/config"), Installed());
  // A variable naming a folder without config/ does not hide the install.
  EXPECT_EQ(ConfigDirFor((root_ / "nowhere").string(), root_ / "prefix" / "bin" / "clothwind", "/built/config"),
            Installed());
}

TEST_F(ConfigDirTest, ABuildTreeProgramFallsBackToTheSourceTreeBuiltFrom) {
  fs::create_directories(root_ / "build" / "bin");
  EXPECT_EQ(ConfigDirFor("", root_ / "build" / "bin" / "clothwind", "/built/config"), "/built/config");
  EXPECT_EQ(ConfigDirFor("", fs::path(), "/built/config"), "/built/config");
}

TEST(DefaultScenePath, NamesTheSceneOfItsKindInTheConfigFolder) {
  const fs::path flag = DefaultScenePath(render::SceneKind::kFlag);
  EXPECT_EQ(flag.filename(), "flag.json");
  EXPECT_EQ(flag.parent_path(), fs::path(ConfigDir()) / "scenes");
  EXPECT_TRUE(fs::exists(flag)) << flag;
  const fs::path cloth = DefaultScenePath(render::SceneKind::kCloth);  // (the flag's alone passed a fixed name)
  EXPECT_EQ(cloth.filename(), "cloth.json");
  EXPECT_TRUE(fs::exists(cloth)) << cloth;
}

}  // namespace
}  // namespace clothwind::data
