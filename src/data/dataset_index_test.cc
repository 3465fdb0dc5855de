#include "data/dataset_index.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <tuple>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "render/render_params.h"

namespace clothwind::data {
namespace {

// A label is the same on every machine: a background photo read from /mnt/a/photos or
// /home/b/photos is recorded by its file name, and the label's ζ reads back as the one rendered
// but for that folder.
TEST(SimExampleLabelTest, RecordsTheBackgroundPhotoByItsFileNameAlone) {
  SimulationSample s;
  s.theta.fill(0.5);
  render::RenderParams zeta = render::SampleRenderParams(render::SceneKind::kFlag, 3);
  ClipInfo info;
  info.dataset = "flag";
  info.split = "train";
  zeta.background_image = "/mnt/a/photos/meadow.jpg";
  const nlohmann::json a = SimExampleLabel("flag-000001-v0", s, zeta, info);
  zeta.background_image = "/home/b/photos/meadow.jpg";
  const nlohmann::json b = SimExampleLabel("flag-000001-v0", s, zeta, info);
  EXPECT_EQ(a, b);
  EXPECT_EQ(a["zeta"]["background_image"], "meadow.jpg");
  render::RenderParams back = LabelZeta(a);
  EXPECT_EQ(back.background_image, "meadow.jpg");
  back.background_image = zeta.background_image;
  EXPECT_EQ(render::ToJson(back), render::ToJson(zeta));
  // Procedural backdrops name none.
  zeta.background_image.clear();
  EXPECT_EQ(SimExampleLabel("flag-000001-v0", s, zeta, info)["zeta"]["background_image"], "");
}

// A frame is whole by its ending: each format the generator writes, whole, one byte short, and
// empty (the file an interrupted copy was writing), and a missing one.
TEST(FrameFileWholeTest, EachFormatWholeIsAndCutShortOrEmptyIsNot) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("clothwind_frame_whole_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  cv::Mat image(24, 32, CV_8UC1);
  cv::randu(image, 0, 256);
  for (const char* ext : {"jpg", "png", "pgm"}) {
    SCOPED_TRACE(ext);
    const std::filesystem::path file = dir / (std::string("000.") + ext);
    ASSERT_TRUE(cv::imwrite(file.string(), image));
    EXPECT_TRUE(FrameFileWhole(file));
    std::filesystem::resize_file(file, std::filesystem::file_size(file) - 1);
    EXPECT_FALSE(FrameFileWhole(file));
    std::filesystem::resize_file(file, 0);
    EXPECT_FALSE(FrameFileWhole(file));
  }
  EXPECT_FALSE(FrameFileWhole(dir / "missing.jpg"));
  std::filesystem::remove_all(dir);
}

TEST(ReadLabelTest, AFrameCountBeyondAnyClipIsRefused) {
  // 1e12 frames wrapped to a negative frame number in get<int>(): the contact sheet asked for
  // "-363689984.jpg".
  namespace fs = std::filesystem;
  const fs::path file = fs::temp_directory_path() / ("clothwind_label_" + std::to_string(::getpid()) + ".json");
  SimulationSample s;
  s.theta.fill(0.5);
  ClipInfo info;
  info.dataset = "flag";
  info.split = "train";
  info.num_frames = 30;
  info.frame_rate = 25;
  info.frame_ext = "jpg";
  nlohmann::json label = SimExampleLabel("flag-000001-v0", s, render::SampleRenderParams(render::SceneKind::kFlag, 3), info);
  std::ofstream(file) << label.dump();
  EXPECT_NO_THROW(ReadLabel(file.string()));
  label["num_frames"] = 1000000000000LL;
  std::ofstream(file) << label.dump();
  try {
    ReadLabel(file.string());
    ADD_FAILURE() << "1e12 frames accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("field 'num_frames' is 1000000000000, expected a positive integer, at most"),
              std::string::npos)
        << e.what();
  }
  // The bound itself: 100000 is read, 100001 refused (1e12 alone passed any bound below it).
  label["num_frames"] = 100000;
  std::ofstream(file) << label.dump();
  EXPECT_NO_THROW(ReadLabel(file.string()));
  label["num_frames"] = 100001;
  std::ofstream(file) << label.dump();
  EXPECT_THROW(ReadLabel(file.string()), std::runtime_error);
  // A simulated clip's simulation and view: "simulation": 1.5 or "view": 99 of 1 was indexed as it
  // was, and eval blamed index.json.
  label["num_frames"] = 30;
  ASSERT_EQ(label["views"], 1);
  for (const auto& [field, value, says] :
       {std::tuple{"simulation", nlohmann::json(1.5), "field 'simulation' is 1.5, expected a whole number >= 0"},
        std::tuple{"simulation", nlohmann::json(-1), "field 'simulation' is -1"},
        std::tuple{"view", nlohmann::json(99), "field 'view' is 99, expected a whole number >= 0, below 'views'"},
        std::tuple{"views", nlohmann::json(0), "field 'views' is 0, expected a whole number >= 1"}}) {
    nlohmann::json bad = label;
    bad[field] = value;
    std::ofstream(file) << bad.dump();
    try {
      ReadLabel(file.string());
      ADD_FAILURE() << field << " " << value << " accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(file.string() + ": " + says), std::string::npos) << e.what();
    }
  }
  fs::remove(file);
}

TEST(ReadIndexTest, AFolderOrAWrongTypedFormatIsRefusedNamingTheFile) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("clothwind_index_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "index.json");  // a folder where the file should be
  auto refusal = [&]() {
    try {
      ReadIndex(dir.string());
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refusal().find((dir / "index.json").string() + ": a folder, expected a JSON file"), std::string::npos) << refusal();
  fs::remove(dir / "index.json");
  std::ofstream(dir / "index.json") << R"({"format": 3, "clips": []})";
  EXPECT_NE(refusal().find("index.json: field 'format' must be \"clothwind-dataset\""), std::string::npos)
      << refusal();
  std::ofstream(dir / "index.json") << R"({"format": "clothwind-dataset", "clips": []})";
  EXPECT_EQ(refusal(), "accepted");
  // make-dataset's header fields: "dataset": "x" failed a resume on a bare iterator error (and
  // --reindex wrote it back), a count of "2" was taken.
  std::ofstream(dir / "index.json") << R"({"format": "clothwind-dataset", "dataset": "x", "clips": []})";
  EXPECT_NE(refusal().find("index.json: field 'dataset' must be an object (make-dataset's settings), got \"x\""),
            std::string::npos)
      << refusal();
  for (const char* count : {"\"2\"", "-1", "2.5"}) {
    std::ofstream(dir / "index.json") << R"({"format": "clothwind-dataset", "dataset": {}, "count": )" << count
                                      << R"(, "clips": []})";
    EXPECT_NE(refusal().find("index.json: field 'count' must be a whole number >= 0 (the simulations), got " +
                             std::string(count)),
              std::string::npos)
        << refusal();
  }
  std::ofstream(dir / "index.json") << R"({"format": "clothwind-dataset", "dataset": {}, "count": 2, "clips": []})";
  EXPECT_EQ(refusal(), "accepted");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::data
