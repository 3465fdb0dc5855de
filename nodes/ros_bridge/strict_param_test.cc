// ParamValue and UnreadParams: the parts of StrictParams that need no ROS master. The nodes'
// reading of a wrong-typed parameter end to end is tests/node_params.test.
#include "ros_bridge/strict_param.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace clothwind::ros_bridge {
namespace {

using ::testing::AllOf;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using XmlRpc::XmlRpcValue;

// The message of the ParamError that reading `v` as T throws ("" when none is thrown).
template <typename T>
std::string Refusal(const XmlRpcValue& v, const std::string& name) {
  try {
    ParamValue<T>(v, name);
  } catch (const ParamError& e) {
    return e.what();
  }
  return "";
}

TEST(StrictParamTest, ADoubleTakesAnIntAndADouble) {
  EXPECT_EQ(ParamValue<double>(XmlRpcValue(5), "~rate"), 5.0);
  EXPECT_EQ(ParamValue<double>(XmlRpcValue(12.5), "~rate"), 12.5);
}

// YAML `rate: "5"` left camera_node at its default 30 Hz without a word.
TEST(StrictParamTest, AQuotedNumberIsRefusedNamingTheParameterAndBothTypes) {
  EXPECT_THAT(Refusal<double>(XmlRpcValue("5"), "~rate"),
              AllOf(HasSubstr("~rate"), HasSubstr("a string (\"5\")"), HasSubstr("expected a double"),
                    HasSubstr("in quotes?")));
  EXPECT_THAT(Refusal<int>(XmlRpcValue("640"), "~width"),
              AllOf(HasSubstr("~width"), HasSubstr("a string"), HasSubstr("expected an int")));
}

TEST(StrictParamTest, AnIntRefusesADouble) {
  EXPECT_EQ(ParamValue<int>(XmlRpcValue(4), "~buffers"), 4);
  EXPECT_THAT(Refusal<int>(XmlRpcValue(2.5), "~buffers"),
              AllOf(HasSubstr("~buffers is set to a double (2.5), expected an int")));
}

// roslaunch stores record_dir:=20261206 as an int: param<std::string> left record_dir empty and
// no clip was recorded. Its decimal text is the folder name, and the note says which text.
TEST(StrictParamTest, AStringTakesAnIntAsItsDecimalTextAndSaysSo) {
  std::string note;
  EXPECT_EQ(ParamValue<std::string>(XmlRpcValue(20261206), "~record_dir", &note), "20261206");
  EXPECT_THAT(note, AllOf(HasSubstr("~record_dir"), HasSubstr("\"20261206\"")));
  EXPECT_EQ(ParamValue<std::string>(XmlRpcValue(-7), "~frame_id", &note), "-7");
  EXPECT_EQ(ParamValue<std::string>(XmlRpcValue("/data/x"), "~record_dir", &note), "/data/x");
  EXPECT_EQ(note, "");  // a string is no conversion
}

// A double's text is lost on the way (1.50 arrives as 1.5), and a bool is no path.
TEST(StrictParamTest, AStringRefusesADoubleAndABool) {
  EXPECT_THAT(Refusal<std::string>(XmlRpcValue(1.5), "~record_dir"),
              AllOf(HasSubstr("~record_dir is set to a double (1.5), expected a string"),
                    HasSubstr("type=\"str\"")));
  EXPECT_THAT(Refusal<std::string>(XmlRpcValue(true), "~camera_name"),
              HasSubstr("~camera_name is set to a bool (true), expected a string"));
}

TEST(StrictParamTest, ABoolTakesTrueFalseAndOneZeroOnly) {
  EXPECT_TRUE(ParamValue<bool>(XmlRpcValue(true), "~loop"));
  EXPECT_FALSE(ParamValue<bool>(XmlRpcValue(false), "~loop"));
  EXPECT_TRUE(ParamValue<bool>(XmlRpcValue(1), "~loop"));
  EXPECT_FALSE(ParamValue<bool>(XmlRpcValue(0), "~loop"));
  EXPECT_THAT(Refusal<bool>(XmlRpcValue(2), "~loop"),
              HasSubstr("~loop is set to an int (2), expected a bool (true/false, or 1/0)"));
  EXPECT_THAT(Refusal<bool>(XmlRpcValue("true"), "~loop"), HasSubstr("a string (\"true\")"));
}

TEST(StrictParamTest, AListOfNumbersNamesTheElementItRefuses) {
  XmlRpcValue roi;
  roi.setSize(3);
  roi[0] = 10;
  roi[1] = 2.5;
  roi[2] = 64;
  EXPECT_THAT(ParamValue<std::vector<double>>(roi, "~roi"), ElementsAre(10.0, 2.5, 64.0));
  roi[1] = "x";
  EXPECT_THAT(Refusal<std::vector<double>>(roi, "~roi"), HasSubstr("~roi[1] is set to a string (\"x\")"));
  EXPECT_THAT(Refusal<std::vector<double>>(XmlRpcValue(3), "~roi"),
              HasSubstr("~roi is set to an int (3), expected a list of numbers"));
  XmlRpcValue empty;
  empty.setSize(0);
  EXPECT_TRUE(ParamValue<std::vector<double>>(empty, "~roi").empty());
}

TEST(StrictParamTest, ADictionaryIsNamedAsOne) {
  XmlRpcValue d;
  d["a"] = 1;
  EXPECT_THAT(Refusal<double>(d, "~rate"), HasSubstr("~rate is set to a dictionary of 1 keys, expected a double"));
}

TEST(StrictParamTest, UnreadParamsAreTheNodesOwnKeysNotAskedFor) {
  const std::vector<std::string> names = {
      "/camera/rate",         "/camera/rat",      // a misspelt key beside the right one
      "/camera/calib/fx",     "/camera/calib/fy", // a dictionary: named once, by its key
      "/camera_2/rat",        "/camera",          // another node whose name starts the same; the namespace itself
      "/rosdistro",           "/camera/diagnostic_period"};
  EXPECT_THAT(UnreadParams(names, "/camera", {"rate", "diagnostic_period"}), ElementsAre("~calib", "~rat"));
  EXPECT_THAT(UnreadParams(names, "/camera/", {"rate", "rat", "calib", "diagnostic_period"}), ElementsAre());
}

}  // namespace
TEST(OutputFileParamTest, AFolderOrAMissingFolderIsRefusedNamingTheParameter) {
  const std::string tmp = std::filesystem::temp_directory_path().string();
  EXPECT_EQ(OutputFileParam("~summary", tmp + "/summary.json"), tmp + "/summary.json");
  EXPECT_EQ(OutputFileParam("~summary", ""), "");
  auto message = [](const std::string& value) {
    try {
      OutputFileParam("~summary", value);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_NE(message(tmp).find("~summary '" + tmp + "' is a folder"), std::string::npos) << message(tmp);
  const std::string missing = tmp + "/clothwind-no-such-folder-" + std::to_string(::getpid()) + "/s.json";
  EXPECT_NE(message(missing).find("does not exist"), std::string::npos) << message(missing);
  EXPECT_NE(message(missing).find("~summary"), std::string::npos) << message(missing);
  const std::string file = tmp + "/clothwind-output-param-" + std::to_string(::getpid());
  std::ofstream(file) << "x";
  EXPECT_NE(message(file + "/s.json").find("is not a folder"), std::string::npos) << message(file + "/s.json");
  std::filesystem::remove(file);
}

TEST(AbsolutePathParamTest, ARelativePathIsMadeAbsoluteFromTheWorkingFolder) {
  const std::string cwd = std::filesystem::current_path().string();
  EXPECT_EQ(AbsolutePathParam("node: ~model", "runs/x/../y/model.pt"), cwd + "/runs/y/model.pt");
  EXPECT_EQ(AbsolutePathParam("node: ~model", "/data/model.pt"), "/data/model.pt");
  EXPECT_EQ(AbsolutePathParam("node: ~model", ""), "");
}

}  // namespace clothwind::ros_bridge
