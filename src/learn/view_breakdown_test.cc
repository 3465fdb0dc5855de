// The breakdown of an evaluation by view: the elevation read from a label's zeta against the
// geometry worked out by hand, groups that recombine into the whole split's metrics, and errors
// that name the label file and field.
#include "learn/view_breakdown.h"

#include <cmath>
#include <fstream>
#include <random>
#include <stdexcept>
#include <unistd.h>

#include <gtest/gtest.h>

namespace clothwind::learn {
namespace {
namespace fs = std::filesystem;

// A simulated clip's label.json with the zeta fields the breakdown reads (FlagSim's flag:
// 3 m x 2 m, hoisted at 4.6 m, so its centre at rest is 5.6 m high).
fs::path WriteLabel(const fs::path& dir, double camera_height, double radius, double angle, const std::string& texture) {
  fs::create_directories(dir);
  const nlohmann::json label = {{"name", dir.filename().string()},
                                {"zeta",
                                 {{"camera_height", camera_height},
                                  {"camera_radius", radius},
                                  {"camera_angle_deg", angle},
                                  {"mesh_height", 4.6},
                                  {"mesh_width", 3.0},
                                  {"mesh_aspect_ratio", 1.5},
                                  {"texture_name", texture}}}};
  std::ofstream(dir / "label.json") << label.dump();
  return dir / "label.json";
}

fs::path TempDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("clothwind_view_breakdown_" + name + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

TEST(ViewBreakdownTest, ElevationIsTheAngleUpToTheFlagsCentreAtRest) {
  const fs::path d = TempDir("elevation");
  // 5.6 m centre, camera 0.6 m high and 5 m away: 45 degrees up.
  ClipView v = ReadClipView(WriteLabel(d / "a", 0.6, 5.0, -12.0, "saltire"));
  EXPECT_NEAR(v.elevation_deg, 45.0, 1e-9);
  EXPECT_DOUBLE_EQ(v.angle_deg, 12.0);  // either side of the side-on view
  EXPECT_DOUBLE_EQ(v.radius_m, 5.0);
  EXPECT_EQ(v.texture, "saltire");
  // Level with the centre: 0; above it: negative (looking down).
  EXPECT_NEAR(ReadClipView(WriteLabel(d / "b", 5.6, 4.0, 0.0, "x")).elevation_deg, 0.0, 1e-9);
  EXPECT_NEAR(ReadClipView(WriteLabel(d / "c", 5.6 + 4.0 * std::sqrt(3.0), 4.0, 0.0, "x")).elevation_deg, -60.0, 1e-9);
  fs::remove_all(d);
}

TEST(ViewBreakdownTest, ALabelWithoutAViewIsRefusedByFileAndField) {
  const fs::path d = TempDir("bad");
  fs::create_directories(d);
  std::ofstream(d / "real.json") << R"({"name": "real", "wind_speed": 3.0})";
  try {
    ReadClipView(d / "real.json");
    FAIL() << "a label without zeta was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("real.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("zeta"), std::string::npos) << e.what();
  }
  std::ofstream(d / "partial.json") << R"({"zeta": {"camera_height": 1, "camera_radius": "far"}})";
  try {
    ReadClipView(d / "partial.json");
    FAIL() << "a zeta without the mesh fields was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("partial.json: zeta."), std::string::npos) << e.what();
  }
  EXPECT_THROW(ReadClipView(d / "missing.json"), std::runtime_error);
  fs::remove_all(d);
}

TEST(ViewBreakdownTest, AViewOutsideTheRenderersRangesIsRefusedByFileAndField) {
  // A radius of -3 m or 1e300 was binned as it was (a 300-digit "camera distance" bin holding
  // both), and an angle of 1e300 deg overflowed its bin's index (undefined behaviour).
  const fs::path d = TempDir("range");
  struct Case {
    double height, radius, angle;
    const char* says;
  };
  for (const Case& c : {Case{0.6, -3.0, 0.0, "zeta.camera_radius is -3, expected in [0.1, 10000] m"},
                        Case{0.6, 1e300, 0.0, "zeta.camera_radius is 1e+300, expected"},
                        Case{0.6, 5.0, 1e300, "zeta.camera_angle_deg is 1e+300, expected"},
                        Case{0.6, 5.0, -361.0, "zeta.camera_angle_deg is -361, expected in [-360, 360] deg"},
                        Case{-1.0, 5.0, 0.0, "zeta.camera_height is -1, expected in (0, 1000] m"}}) {
    const fs::path label = WriteLabel(d / "a", c.height, c.radius, c.angle, "x");
    try {
      ReadClipView(label);
      ADD_FAILURE() << c.says << ": read";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(label.string() + ": " + c.says), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(ReadClipView(WriteLabel(d / "a", 1000.0, 1e4, -360.0, "x")));
  fs::remove_all(d);
}

TEST(ViewBreakdownTest, BinsStartAtTheLowestKeyAndHoldOnlyTheirExamples) {
  // Keys 21, 24, 33 in 5-wide bins from 20: [20, 25) holds two, [25, 30) none (left out), [30, 35) one.
  const std::vector<BinMetrics> b = ComputeBinnedMetrics({21, 33, 24}, {1, 2, 3}, {1.2, 2.0, 2.0}, 5.0);
  ASSERT_EQ(b.size(), 2u);
  EXPECT_DOUBLE_EQ(b[0].lo, 20.0);
  EXPECT_DOUBLE_EQ(b[0].hi, 25.0);
  EXPECT_EQ(b[0].metrics.count, 2);
  EXPECT_NEAR(b[0].metrics.rmse, std::sqrt((0.04 + 1.0) / 2), 1e-12);
  EXPECT_NEAR(b[0].metrics.bias, (0.2 - 1.0) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(b[1].lo, 30.0);
  EXPECT_EQ(b[1].metrics.count, 1);
  EXPECT_DOUBLE_EQ(b[1].metrics.rmse, 0.0);
  EXPECT_TRUE(ComputeBinnedMetrics({}, {}, {}, 1.0).empty());
  EXPECT_THROW(ComputeBinnedMetrics({1}, {1}, {}, 1.0), std::invalid_argument);
  EXPECT_THROW(ComputeBinnedMetrics({1}, {1}, {1}, 0.0), std::invalid_argument);
}

TEST(ViewBreakdownTest, EveryGroupingRecombinesIntoTheWholeSplit) {
  // Random views and errors: within each parameter the groups' counts add up to n and their
  // squared errors to the whole split's.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> height(0.2, 3), radius(4, 6), angle(-15, 15), speed(0, 10), noise(-1, 1);
  const fs::path d = TempDir("recombine");
  const std::vector<std::string> textures = {"saltire", "five_bands", "quartered"};
  EvalResult r;
  for (int i = 0; i < 200; ++i) {
    r.dirs.push_back(d / ("clip" + std::to_string(i)));
    WriteLabel(r.dirs.back(), height(rng), radius(rng), angle(rng), textures[i % 3]);
    r.truth.push_back(speed(rng));
    r.predicted.push_back(r.truth.back() + noise(rng) * (i % 3 == 1 ? 2.0 : 0.5));  // five_bands errs most
  }
  const Metrics all = ComputeMetrics(r.truth, r.predicted);
  const ViewBreakdown b = BreakDownByView(r);
  for (const auto* bins : {&b.elevation, &b.angle, &b.radius}) {
    int count = 0;
    double se = 0;
    for (const BinMetrics& bin : *bins) {
      count += bin.metrics.count;
      se += bin.metrics.rmse * bin.metrics.rmse * bin.metrics.count;
    }
    EXPECT_EQ(count, 200);
    EXPECT_NEAR(std::sqrt(se / count), all.rmse, 1e-9);
  }
  // FlagSim's cameras see the centre 23.4-53.5 degrees up; bins are whole multiples of 5.
  EXPECT_GE(b.elevation.front().lo, 20.0);
  EXPECT_DOUBLE_EQ(std::fmod(b.elevation.front().lo, 5.0), 0.0);
  EXPECT_LE(b.elevation.back().hi, 55.0);
  ASSERT_EQ(b.texture.size(), 3u);
  EXPECT_EQ(b.texture.front().name, "five_bands");  // worst first
  EXPECT_EQ(b.texture.front().metrics.count, 67);
  const nlohmann::json j = ViewBreakdownJson(b);
  EXPECT_EQ(j["texture"][0]["name"], "five_bands");
  EXPECT_EQ(j["camera_elevation_deg"].size(), b.elevation.size());
  EXPECT_NE(ViewBreakdownTable(b).find("five_bands"), std::string::npos);
  // A view missing for an example is an error, not a shorter table.
  EXPECT_THROW(BreakDownByView(r, std::vector<ClipView>(199)), std::invalid_argument);
  fs::remove_all(d);
}

}  // namespace
}  // namespace clothwind::learn
