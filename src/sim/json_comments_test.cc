#include "sim/json_comments.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace clothwind::sim {
namespace {

TEST(StripJsonComments, RemovesLineAndBlockCommentsOutsideStrings) {
  const std::string text =
      "{ // a line comment\n"
      "  \"a\": 1, /* block\n"
      "  spanning lines */ \"b\": \"http://x/*y*/\",\n"
      "  \"c\": \"quote \\\" // not a comment\"\n"
      "}\n";
  const std::string stripped = StripJsonComments(text);
  EXPECT_EQ(stripped.size(), text.size());
  const auto j = nlohmann::json::parse(stripped);
  EXPECT_EQ(j.at("a").get<int>(), 1);
  EXPECT_EQ(j.at("b").get<std::string>(), "http://x/*y*/");
  EXPECT_EQ(j.at("c").get<std::string>(), "quote \" // not a comment");
  // Newlines survive, so parser positions still match the original file.
  EXPECT_EQ(std::count(stripped.begin(), stripped.end(), '\n'),
            std::count(text.begin(), text.end(), '\n'));
}

TEST(StripJsonComments, UnterminatedBlockCommentNamesItsLine) {
  try {
    StripJsonComments("{\n\"a\": 1 /* open\n}");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
  }
}

TEST(StripJsonComments, PlainJsonUnchanged) {
  const std::string text = "{\"x\": [1, 2, 3], \"s\": \"a/b\"}";
  EXPECT_EQ(StripJsonComments(text), text);
}

}  // namespace
}  // namespace clothwind::sim
