// ReadJsonFile's errors on the files people get wrong: none there, a folder, an empty file, a
// truncated one, a NaN; and JsonErrorText on nlohmann's own messages.
#include "common/json_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace clothwind {
namespace {
namespace fs = std::filesystem;

class JsonFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("clothwind_json_file_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    std::ofstream((dir_ / name).string()) << text;
    return (dir_ / name).string();
  }
  // The message ReadJsonFile throws for `path`.
  static std::string Error(const std::string& path, const std::string& what = "") {
    try {
      ReadJsonFile(path, what);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path dir_;
};

TEST_F(JsonFileTest, ReadsAValidFile) {
  EXPECT_EQ(ReadJsonFile(Write("a.json", "{\"speed\": 3.5}\n"))["speed"], 3.5);
}

TEST_F(JsonFileTest, NamesTheFileAndWhatIsWrongWithoutLibraryText) {
  const std::string missing = (dir_ / "missing.json").string();
  EXPECT_EQ(Error(missing), missing + ": cannot open: No such file or directory");
  EXPECT_EQ(Error(dir_.string()), dir_.string() + ": a folder, expected a JSON file");
  const std::string empty = Write("empty.json", "");
  EXPECT_EQ(Error(empty), empty + ": the file is empty, expected JSON");
  const std::string blank = Write("blank.json", "\n  \n");
  EXPECT_EQ(Error(blank, "the model's architecture"),
            blank + ": the file is empty but for whitespace, expected JSON (the model's architecture)");
  const std::string cut = Write("cut.json", "{\"speed\": ");
  EXPECT_EQ(Error(cut), cut + ": not valid JSON: line 1, column 11: unexpected end of input; expected '[', '{', or a literal");
  const std::string nan = Write("nan.json", "{\n  \"speed\": NaN\n}\n");
  const std::string e = Error(nan);
  EXPECT_EQ(e.rfind(nan + ": not valid JSON: line 2, column 12: invalid literal", 0), 0u) << e;
  for (const std::string& message : {Error(missing), Error(empty), Error(cut), e})
    EXPECT_EQ(message.find("json.exception"), std::string::npos) << message;
}

TEST_F(JsonFileTest, ReadsAPipe) {
  // `clothwind simulate <(...)`: a pipe is no regular file, and is read.
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  const std::string text = "{\"a\": 1}";
  ASSERT_EQ(::write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
  ::close(fds[1]);
  EXPECT_EQ(ReadJsonFile("/proc/self/fd/" + std::to_string(fds[0]))["a"], 1);
  ::close(fds[0]);
}

TEST(JsonErrorText, DropsTheLibrarysTagAndGenericWords) {
  try {
    nlohmann::json j = nullptr;
    (void)j.get<double>();
    FAIL();
  } catch (const nlohmann::json::exception& e) {
    EXPECT_EQ(JsonErrorText(e), "type must be number, but is null");
  }
  EXPECT_EQ(JsonErrorText(std::runtime_error("plain")), "plain");
}

}  // namespace
}  // namespace clothwind
