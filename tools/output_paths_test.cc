#include "output_paths.h"

#include <unistd.h>

#include <fstream>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind::tools {
namespace {
namespace fs = std::filesystem;

TEST(OutputPathsTest, AnOutputThatIsAnInputIsRefusedHoweverSpelt) {
  const fs::path dir = fs::temp_directory_path() / ("clothwind_output_paths_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "run");
  std::ofstream(dir / "run" / "model.pt") << "weights";
  std::ofstream(dir / "run" / "model.json") << "{}";
  const std::vector<fs::path> inputs = {dir / "run" / "model.pt", dir / "run" / "model.json"};
  // The same file through another spelling (eval --plot run/../run/model.pt replaced the model).
  try {
    RefuseOutputOverInput("--plot", dir / "run" / ".." / "run" / "model.pt", inputs);
    ADD_FAILURE() << "the model was accepted as the plot";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--plot"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("is an input"), std::string::npos) << e.what();
  }
  EXPECT_THROW(RefuseOutputOverInput("--json", dir / "run" / "model.json", inputs), std::invalid_argument);
  // Outputs not written yet, other files and no output at all pass.
  EXPECT_NO_THROW(RefuseOutputOverInput("--json", dir / "run" / "eval.json", inputs));
  EXPECT_NO_THROW(RefuseOutputOverInput("--json", fs::path(), inputs));
  EXPECT_NO_THROW(RefuseOutputOverInput("--json", dir / "run" / "eval.json", {fs::path()}));
  // An output not written yet that names an input not there either: the same path is refused.
  EXPECT_THROW(RefuseOutputOverInput("--out", dir / "new.pt", {dir / "." / "new.pt"}), std::invalid_argument);
  fs::remove_all(dir);
}

TEST(OutputPathsTest, AnOutputOnAFolderOrUnderAFileIsRefusedBeforeTheWork) {
  const fs::path dir = fs::temp_directory_path() / ("clothwind_output_writable_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "sub");
  std::ofstream(dir / "file") << "x";
  for (const fs::path& bad : {dir / "sub", dir / "file" / "e.json", dir / "file" / "a" / "e.json"}) {
    try {
      RefuseUnwritableOutput("--json", bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--json " + bad.string()), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(RefuseUnwritableOutput("--json", dir / "sub" / "e.json"));
  // A missing folder is made by the verb, as every verb's outputs' (eval refused it, simulate
  // made it): accepted, checked where it will be made, and made by MakeFoldersFor.
  EXPECT_NO_THROW(RefuseUnwritableOutput("--json", dir / "new" / "deeper" / "e.json"));
  EXPECT_FALSE(fs::exists(dir / "new"));
  {
    MadeFolders made = MakeFoldersFor("--json", dir / "new" / "deeper" / "e.json");
    EXPECT_TRUE(fs::is_directory(dir / "new" / "deeper"));
    EXPECT_FALSE(fs::exists(dir / "new" / "deeper" / "e.json"));
    EXPECT_EQ(made.made(), (std::vector<fs::path>{dir / "new", dir / "new" / "deeper"}));
    made.Keep();
  }
  EXPECT_TRUE(fs::is_directory(dir / "new" / "deeper")) << "kept folders were removed";
  // Not kept (the verb failed, or had nothing to write): the folders it made go again while empty,
  // innermost first; a folder that was there before stays, and so does one a file went into.
  {
    const MadeFolders made = MakeFoldersFor("--plot", dir / "new" / "a" / "b" / "p.png");
    EXPECT_EQ(made.made(), (std::vector<fs::path>{dir / "new" / "a", dir / "new" / "a" / "b"}));
  }
  EXPECT_FALSE(fs::exists(dir / "new" / "a")) << "an unused folder was left behind";
  // An empty folder that was there before, on the way: not the verb's to take away.
  fs::create_directories(dir / "empty_before");
  { const MadeFolders made = MakeFoldersFor("--plot", dir / "empty_before" / "x" / "p.png"); }
  EXPECT_FALSE(fs::exists(dir / "empty_before" / "x"));
  EXPECT_TRUE(fs::is_directory(dir / "empty_before")) << "an empty folder there before was removed";
  // A folder another run took away while this one worked is made again before the write.
  RemakeFolderFor(dir / "shared" / "results" / "b.json");
  EXPECT_TRUE(fs::is_directory(dir / "shared" / "results"));
  EXPECT_NO_THROW(RemakeFolderFor(dir / "file" / "x.json"));  // the write that follows names it
  {
    const MadeFolders made = MakeFoldersFor("--plot", dir / "new" / "c" / "d" / "p.png");
    std::ofstream(dir / "new" / "c" / "kept.txt") << "x";
  }
  EXPECT_TRUE(fs::exists(dir / "new" / "c" / "kept.txt")) << "a folder holding a file was removed";
  EXPECT_FALSE(fs::exists(dir / "new" / "c" / "d"));
  // One that cannot be made is named by its option, output and folder.
  try {
    const MadeFolders made = MakeFoldersFor("--plot", dir / "file" / "p.png");
    ADD_FAILURE() << "a folder made where a file is";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--plot " + (dir / "file" / "p.png").string() + ": cannot make its folder " +
                                              (dir / "file").string(), 0), 0u) << e.what();
  }
  EXPECT_THROW(RefuseUnwritableOutput("--json", "/proc/new/e.json"), std::invalid_argument);
  EXPECT_NO_THROW(RefuseUnwritableOutput("--json", "e.json"));  // the working folder
  EXPECT_NO_THROW(RefuseUnwritableOutput("--json", fs::path()));
  // A folder that takes no new file (root writes everywhere but /proc): refused before the work,
  // and a probe that worked leaves nothing behind.
  try {
    RefuseUnwritableOutput("--json", "/proc/x.json");
    ADD_FAILURE() << "/proc/x.json accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--json /proc/x.json: cannot write in /proc (", 0), 0u) << e.what();
  }
  EXPECT_THROW(RefuseUnwritableFolder("--out", "/proc/new/m.pt"), std::invalid_argument);
  EXPECT_NO_THROW(RefuseUnwritableFolder("--out", dir / "a" / "b" / "m.pt"));  // made by the verb
  EXPECT_FALSE(fs::exists(dir / "a"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "sub"), {}), 0);
  // Output folders: one that exists or will be made is fine, one under a file or a symbolic link
  // to nothing is refused (the link passed, and the work failed later: "File exists").
  EXPECT_NO_THROW(RefuseUnwritableOutputFolder("--out", dir / "sub"));
  EXPECT_NO_THROW(RefuseUnwritableOutputFolder("--out", dir / "new" / "deeper"));
  std::ofstream(dir / "plain") << "x";
  fs::create_symlink(dir / "nowhere", dir / "dangling");
  for (const auto& [bad, says] : {std::pair{dir / "plain" / "run", "plain is a file, not a folder"},
                                  std::pair{dir / "dangling" / "run", "dangling is a symbolic link to nothing"}}) {
    try {
      RefuseUnwritableOutputFolder("--out", bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir / "sub"), {}), 0);  // no probe left behind
  // A run written into the dataset, or into one of its clips, is refused; beside it is not.
  fs::create_directories(dir / "data" / "toy-00000");
  EXPECT_THROW(RefuseOutputInsideFolder("--out", dir / "data", dir / "data", "the dataset"), std::invalid_argument);
  EXPECT_THROW(RefuseOutputInsideFolder("--out", dir / "data" / "toy-00000" / "run", dir / "data" / ".", "the dataset"),
               std::invalid_argument);
  EXPECT_NO_THROW(RefuseOutputInsideFolder("--out", dir / "data-run", dir / "data", "the dataset"));
  // A relative --out that does not exist yet, from inside the dataset (`--data . --out run`).
  const fs::path here = fs::current_path();
  fs::current_path(dir / "data");
  EXPECT_THROW(RefuseOutputInsideFolder("--out", "run", ".", "the dataset"), std::invalid_argument);
  fs::current_path(here);
  EXPECT_NO_THROW(RefuseOutputInsideFolder("--out", dir / "run", dir / "data", "the dataset"));
  // Verbs that make a missing folder themselves refuse only a folder.
  EXPECT_THROW(RefuseFolderAsOutput("--out", dir / "sub"), std::invalid_argument);
  EXPECT_NO_THROW(RefuseFolderAsOutput("--out", dir / "no_such_folder" / "m.pt"));
  EXPECT_NO_THROW(RefuseFolderAsOutput("--out", fs::path()));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::tools
