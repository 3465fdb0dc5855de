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

TEST(ParseJsonWithComments, RefusesAKeyGivenTwiceInOneObjectNamingWhere) {
  EXPECT_EQ(ParseJsonWithComments("{\"a\": 1, // note\n \"b\": [1, {\"a\": 2}]}")["b"][1]["a"], 2);
  auto error_of = [](const std::string& text) {
    try {
      ParseJsonWithComments(text);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("{\"a\": 1, \"a\": 2}").find("\"a\" is given twice in the top-level object"), std::string::npos)
      << error_of("{\"a\": 1, \"a\": 2}");
  const std::string nested = "{\"c\": [3, {\"x\": 1}, {\"m\": {\"k\": 1, \"k\": 1}}]}";
  EXPECT_NE(error_of(nested).find("\"k\" is given twice in c[2].m"), std::string::npos) << error_of(nested);
  // Invalid JSON is still the parser's own error, with its byte offset.
  EXPECT_THROW(ParseJsonWithComments("{\"a\": }"), nlohmann::json::parse_error);
}

TEST(ParseJsonWithComments, RefusesNestingDeeperThanTheLimitNamingTheLine) {
  // Copying or printing a parsed value recurses once per level: 2,000,000 levels overflowed the
  // stack of the scene reader. kMaxJsonDepth levels parse; one more is refused on its line.
  auto nested = [](int depth) { return std::string(depth, '[') + std::string(depth, ']'); };
  EXPECT_NO_THROW(ParseJsonWithComments("{\"a\":\n" + nested(kMaxJsonDepth - 1) + "}"));
  try {
    ParseJsonWithComments("{\"a\":\n\n" + nested(kMaxJsonDepth) + "}");
    ADD_FAILURE() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("line 3: arrays and objects nested more than 256 deep"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ParseJsonWithComments(nested(2000000)), std::runtime_error);
  // Brackets in strings and comments are not nesting.
  const std::string quoted = "{\"s\": \"" + std::string(1000, '[') + "\\\"\", // " + std::string(1000, '{') +
                             "\n /* " + std::string(1000, '[') + " */ \"t\": 1}";
  EXPECT_EQ(ParseJsonWithComments(quoted)["t"], 1);
}

}  // namespace
}  // namespace clothwind::sim
