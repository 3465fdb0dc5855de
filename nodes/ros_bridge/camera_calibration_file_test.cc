// CheckCalibrationFile and CalibrationFilePath: what camera_node refuses to give
// camera_info_manager (the parser under it aborted the node on these files).
#include "ros_bridge/camera_calibration_file.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace clothwind::ros_bridge {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// A calibration for 40x30 images with each matrix as camera_calibration writes it.
std::string Calibration(const std::string& k_rows = "3", const std::string& k_data = "[35, 0, 19.5, 0, 36, 14.5, 0, 0, 1]",
                        const std::string& d = "rows: 1\n  cols: 5\n  data: [0.1, -0.2, 0, 0, 0]") {
  return "image_width: 40\nimage_height: 30\ncamera_name: test_camera\n"
         "camera_matrix:\n  rows: " + k_rows + "\n  cols: 3\n  data: " + k_data + "\n"
         "distortion_model: plumb_bob\ndistortion_coefficients:\n  " + d + "\n"
         "rectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
         "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [35, 0, 19.5, 0, 0, 36, 14.5, 0, 0, 0, 1, 0]\n";
}

class CameraCalibrationFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/camera_calibration_file_test_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { std::system(("rm -rf '" + dir_ + "'").c_str()); }

  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path) << text;
    return path;
  }

  std::string dir_;
};

TEST_F(CameraCalibrationFileTest, AWholeCalibrationAndAMissingFilePass) {
  EXPECT_EQ(CheckCalibrationFile(Write("good.yaml", Calibration())), "");
  // Not there yet: camera_info_manager says so, and set_camera_info writes it there.
  EXPECT_EQ(CheckCalibrationFile(dir_ + "/none.yaml"), "");
}

// A folder (named .yaml or not) threw "Is a directory" out of the parser: SIGABRT.
TEST_F(CameraCalibrationFileTest, AFolderIsRefused) {
  EXPECT_THAT(CheckCalibrationFile(dir_), AllOf(HasSubstr(dir_), HasSubstr("is a directory")));
  const std::string folder = dir_ + "/calib.yaml";
  ASSERT_EQ(mkdir(folder.c_str(), 0755), 0);
  EXPECT_THAT(CheckCalibrationFile(folder), HasSubstr("is a directory"));
}

// rows/cols other than CameraInfo's failed an assert in the parser: SIGABRT.
TEST_F(CameraCalibrationFileTest, AMatrixOfAnotherShapeIsRefused) {
  EXPECT_THAT(CheckCalibrationFile(Write("k4.yaml", Calibration("4", "[35, 0, 19.5, 0, 36, 14.5, 0, 0, 1, 0, 0, 0]"))),
              AllOf(HasSubstr("k4.yaml"), HasSubstr("camera_matrix is 4x3, CameraInfo's is 3x3")));
}

// Data longer than rows x cols were cut without a word, shorter ones half read.
TEST_F(CameraCalibrationFileTest, DataOfAnotherLengthThanRowsTimesColsAreRefused) {
  EXPECT_THAT(CheckCalibrationFile(Write("k10.yaml", Calibration("3", "[35, 0, 19.5, 0, 36, 14.5, 0, 0, 1, 7]"))),
              HasSubstr("camera_matrix: rows x cols is 3x3 = 9 values, data has 10"));
  EXPECT_THAT(CheckCalibrationFile(Write("d.yaml", Calibration("3", "[35, 0, 19.5, 0, 36, 14.5, 0, 0, 1]",
                                                                 "rows: 1\n  cols: 2\n  data: [0.1, -0.2, 0, 0, 0]"))),
              HasSubstr("distortion_coefficients: rows x cols is 1x2 = 2 values, data has 5"));
  // D of any whole shape is read (its length is the distortion model's business).
  EXPECT_EQ(CheckCalibrationFile(Write("d8.yaml", Calibration("3", "[35, 0, 19.5, 0, 36, 14.5, 0, 0, 1]",
                                                               "rows: 1\n  cols: 8\n  data: [0, 0, 0, 0, 0, 0, 0, 0]"))),
            "");
}

TEST_F(CameraCalibrationFileTest, BrokenYamlAndNonNumbersAreRefused) {
  EXPECT_THAT(CheckCalibrationFile(Write("syntax.yaml", "camera_matrix: [1, 2\n")), HasSubstr("is not YAML"));
  EXPECT_THAT(CheckCalibrationFile(Write("list.yaml", "- 1\n- 2\n")), HasSubstr("is not a YAML mapping"));
  EXPECT_THAT(CheckCalibrationFile(Write("nan.yaml", Calibration("3", "[35, 0, x, 0, 36, 14.5, 0, 0, 1]"))),
              HasSubstr("camera_matrix: data[2] is not a number"));
  EXPECT_THAT(CheckCalibrationFile(Write("rows.yaml", Calibration("three"))), HasSubstr("whole numbers"));
  // Not YAML by its name (a Videre .ini): only its being a file is checked.
  EXPECT_EQ(CheckCalibrationFile(Write("c.ini", "[image]\n")), "");
}

// A key given twice was read as its first ("image_width: 64" over "image_width: 640"), a negative
// focal length (a sign lost in an edit) and a size of 0 were taken.
TEST_F(CameraCalibrationFileTest, AKeyGivenTwiceANegativeFocalLengthOrAnEmptySizeIsRefused) {
  EXPECT_THAT(CheckCalibrationFile(Write("twice.yaml", "image_width: 64\n" + Calibration())),
              AllOf(HasSubstr("twice.yaml"), HasSubstr("key image_width is given twice")));
  std::string nested = Calibration();
  nested.replace(nested.find("  rows: 3\n  cols: 3\n  data: [35"), 0, "  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n");
  EXPECT_THAT(CheckCalibrationFile(Write("nested.yaml", nested)), HasSubstr("key camera_matrix.data is given twice"));
  EXPECT_THAT(CheckCalibrationFile(Write("fx.yaml", Calibration("3", "[-5, 0, 19.5, 0, 36, 14.5, 0, 0, 1]"))),
              AllOf(HasSubstr("fx.yaml"), HasSubstr("fx and fy (data[0], data[4]) must be > 0 [px], got -5 and 36")));
  EXPECT_THAT(CheckCalibrationFile(Write("fy.yaml", Calibration("3", "[35, 0, 19.5, 0, 0, 14.5, 0, 0, 1]"))),
              HasSubstr("got 35 and 0"));
  std::string empty = Calibration();
  empty.replace(empty.find("image_height: 30"), 16, "image_height: 0");
  EXPECT_THAT(CheckCalibrationFile(Write("h0.yaml", empty)), HasSubstr("image_height must be > 0 [px], got 0"));
}

// A distortion model image_geometry does not know (a typo) was taken, and every consumer then
// rectified with no distortion at all.
TEST_F(CameraCalibrationFileTest, AnUnknownDistortionModelIsRefused) {
  std::string typo = Calibration();
  typo.replace(typo.find("plumb_bob"), 9, "plumb_bobb");
  EXPECT_THAT(CheckCalibrationFile(Write("typo.yaml", typo)),
              AllOf(HasSubstr("typo.yaml"), HasSubstr("distortion_model is 'plumb_bobb', expected plumb_bob")));
  for (const std::string model : {"rational_polynomial", "equidistant", "''"}) {
    std::string other = Calibration();
    other.replace(other.find("plumb_bob"), 9, model);
    EXPECT_EQ(CheckCalibrationFile(Write("other.yaml", other)), "") << model;
  }
}

TEST(CalibrationFilePathTest, FileAndPackageUrlsNameTheirFile) {
  const auto packages = [](const std::string& name) { return name == "clothwind" ? "/src/clothwind" : ""; };
  EXPECT_EQ(CalibrationFilePath("file:///a/b.yaml", packages), "/a/b.yaml");
  EXPECT_EQ(CalibrationFilePath("FILE:///a/b.yaml", packages), "/a/b.yaml");
  EXPECT_EQ(CalibrationFilePath("package://clothwind/config/c.yaml", packages), "/src/clothwind/config/c.yaml");
  EXPECT_EQ(CalibrationFilePath("package://nothere/c.yaml", packages), "");
  EXPECT_EQ(CalibrationFilePath("http://example.com/c.yaml", packages), "");
}

}  // namespace
}  // namespace clothwind::ros_bridge
