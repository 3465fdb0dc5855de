#include "learn/track_targets.h"

#include <unistd.h>

#include <array>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace clothwind::learn {
namespace {

namespace fs = std::filesystem;

// Tracks of a cols x rows grid on size x size frames; point p at x(p, t), y(p, t).
template <typename X, typename Y>
Tracks MakeTracks(int cols, int rows, int size, int frames, X x, Y y) {
  Tracks t;
  t.cols = cols;
  t.rows = rows;
  t.width = t.height = size;
  t.frames = frames;
  for (int k = 0; k < frames; ++k)
    for (int p = 0; p < cols * rows; ++p) {
      t.xy.push_back(static_cast<float>(x(p, k)));
      t.xy.push_back(static_cast<float>(y(p, k)));
    }
  return t;
}

// Index of a point's target: 0, 1 the u, v means; 2 + j - 1 u's bin j; 2 + kTrackBins + j - 1 v's.
int UMean(int p) { return p * kTargetsPerPoint; }
int VMean(int p) { return p * kTargetsPerPoint + 1; }
int UBin(int p, int j) { return p * kTargetsPerPoint + 1 + j; }
int VBin(int p, int j) { return p * kTargetsPerPoint + 1 + kTrackBins + j; }

TEST(TrackTargetsTest, ASinusoidReadsHalfItsAmplitudeAtItsBinAQuarterNextToItAndNothingElsewhere) {
  // Point 0 swings 3 px left-right at bin 2 of a 30-frame window about the frame's centre;
  // point 1 stands 32 px below the centre.
  const int T = 30;
  const Tracks t = MakeTracks(
      1, 2, 128, 60, [&](int p, int k) { return p == 0 ? 64.0 + 3.0 * std::sin(2 * M_PI * 2 * k / T) : 64.0; },
      [](int p, int) { return p == 0 ? 64.0 : 96.0; });
  const std::vector<float> y = TrackTargets(t, 0, T, cv::Rect(0, 0, 128, 128), 128, false);
  ASSERT_EQ(y.size(), 2u * kTargetsPerPoint);
  EXPECT_NEAR(y[UMean(0)], 0.0, 1e-6);
  EXPECT_NEAR(y[VMean(0)], 0.0, 1e-6);
  EXPECT_NEAR(y[VMean(1)], 0.5, 1e-6);
  const double amplitude = 2.0 * 3.0 / 128;  // 3 px in units of half the frame
  EXPECT_NEAR(y[UBin(0, 2)], std::log(1e-4 + amplitude / 2), 1e-4);
  // The Hann window's spectrum is (1/2, -1/4, -1/4) at bins (0, ±1): the neighbours read half as much.
  EXPECT_NEAR(y[UBin(0, 1)], std::log(1e-4 + amplitude / 4), 1e-4);
  EXPECT_NEAR(y[UBin(0, 3)], std::log(1e-4 + amplitude / 4), 1e-4);
  for (int j = 1; j <= kTrackBins; ++j) {
    if (j > 3) {
      EXPECT_LT(y[UBin(0, j)], std::log(2e-4)) << j;  // nothing leaks further
    }
    EXPECT_NEAR(y[VBin(0, j)], std::log(1e-4), 1e-6) << j;       // no vertical motion
    EXPECT_NEAR(y[UBin(1, j)], std::log(1e-4), 1e-6) << j;
  }
}

TEST(TrackTargetsTest, FlippingNegatesTheHorizontalMeansAndKeepsTheMotion) {
  const Tracks t = MakeTracks(
      2, 2, 128, 40, [](int p, int k) { return 20.0 + 25 * p + 2.0 * std::cos(0.7 * k + p); },
      [](int p, int k) { return 50.0 + 10 * p + std::sin(0.3 * k); });
  const std::vector<float> a = TrackTargets(t, 5, 30, cv::Rect(0, 0, 128, 128), 128, false);
  const std::vector<float> b = TrackTargets(t, 5, 30, cv::Rect(0, 0, 128, 128), 128, true);
  for (int p = 0; p < 4; ++p) {
    EXPECT_NEAR(b[UMean(p)], -a[UMean(p)], 1e-6);
    EXPECT_NEAR(b[VMean(p)], a[VMean(p)], 1e-6);
    for (int j = 1; j <= kTrackBins; ++j) {
      EXPECT_NEAR(b[UBin(p, j)], a[UBin(p, j)], 1e-5);
      EXPECT_NEAR(b[VBin(p, j)], a[VBin(p, j)], 1e-5);
    }
  }
}

TEST(TrackTargetsTest, PositionsAreInTheCropAndInTheFramesTheCropWasTakenFrom) {
  // A point fixed at (96, 64) px of a 128-px frame.
  const Tracks t = MakeTracks(1, 2, 128, 30, [](int, int) { return 96.0; }, [](int, int) { return 64.0; });
  // The crop's right edge: u = 1, v = 0 at the crop's centre row.
  std::vector<float> y = TrackTargets(t, 0, 30, cv::Rect(32, 32, 64, 64), 128, false);
  EXPECT_NEAR(y[UMean(0)], 1.0, 1e-6);
  EXPECT_NEAR(y[VMean(0)], 0.0, 1e-6);
  // A frame cache's 64-px squares of the same frames: the point is at (48, 32) of them.
  y = TrackTargets(t, 0, 30, cv::Rect(0, 0, 64, 64), 64, false);
  EXPECT_NEAR(y[UMean(0)], 0.5, 1e-6);
  EXPECT_NEAR(y[VMean(0)], 0.0, 1e-6);
}

TEST(TrackTargetsTest, TheWindowIsTheSamplesFrames) {
  // A point that stands still until frame 30 and then oscillates: window 0 shows no motion,
  // window 30 the oscillation.
  const Tracks t = MakeTracks(
      1, 2, 128, 60, [](int, int k) { return k < 30 ? 64.0 : 64.0 + 4 * std::sin(2 * M_PI * k / 10); },
      [](int, int) { return 64.0; });
  const std::vector<float> still = TrackTargets(t, 0, 30, cv::Rect(0, 0, 128, 128), 128, false);
  const std::vector<float> moving = TrackTargets(t, 30, 30, cv::Rect(0, 0, 128, 128), 128, false);
  EXPECT_NEAR(still[UBin(0, 3)], std::log(1e-4), 1e-6);
  EXPECT_GT(moving[UBin(0, 3)], std::log(0.02));
  EXPECT_THROW(TrackTargets(t, 31, 30, cv::Rect(0, 0, 128, 128), 128, false), std::invalid_argument);
}

// Four points of a 2x2 grid, each moving on its own, for one-frame windows.
Tracks TravellingWaveForOneFrame() {
  return MakeTracks(
      2, 2, 128, 10, [](int p, int k) { return 30.0 + 20 * p + 3 * std::sin(0.7 * k + p); },
      [](int p, int k) { return 50.0 + 10 * p + 2 * std::cos(0.5 * k); });
}

TEST(TrackTargetsTest, AOneFrameWindowHoldsThatFramesPositionsAndNoMotion) {
  // A per-frame network (--frames 1) learns where the points are in its one frame; the moving
  // point's amplitudes and phases must read "no motion", not the NaN of an all-zero Hann window.
  const Tracks t = TravellingWaveForOneFrame();
  for (int k : {0, 7}) {
    const std::vector<float> y = TrackTargets(t, k, 1, cv::Rect(0, 0, 128, 128), 128, false, 2);
    ASSERT_EQ(y.size(), static_cast<size_t>(TrackTargetCount(4, 2)));
    for (int p = 0; p < 4; ++p) {
      EXPECT_NEAR(y[UMean(p)], 2.0 * t.xy[(k * 4 + p) * 2] / 128 - 1, 1e-6) << k << " " << p;
      EXPECT_NEAR(y[VMean(p)], 2.0 * t.xy[(k * 4 + p) * 2 + 1] / 128 - 1, 1e-6) << k << " " << p;
      for (int j = 1; j <= kTrackBins; ++j) {
        EXPECT_FLOAT_EQ(y[UBin(p, j)], std::log(1e-4f)) << p << " " << j;
        EXPECT_FLOAT_EQ(y[VBin(p, j)], std::log(1e-4f)) << p << " " << j;
      }
    }
    for (size_t i = 4 * kTargetsPerPoint; i < y.size(); ++i) EXPECT_EQ(y[i], 0.0f) << i;
  }
  EXPECT_THROW(TrackTargets(t, 0, 0, cv::Rect(0, 0, 128, 128), 128, false), std::invalid_argument);
}

// Index of point p's phase target at bin j (of `bins`): coordinate c (0 u, 1 v), part 0 re, 1 im.
int Phase(int points, int bins, int p, int j, int c, int part) {
  return points * kTargetsPerPoint + (p * bins + j - 1) * kPhaseTargetsPerPointAndBin + c * 2 + part;
}

// A wave travelling from hoist to fly at bin 2 of a 30-frame window: point p's u lags the fly
// corner's v by 0.6 · (points - 1 - p) rad; its amplitude grows with p.
Tracks TravellingWave(int frames) {
  const int points = 4, T = 30;
  return MakeTracks(
      2, 2, 128, frames,
      [&](int p, int k) { return 40.0 + 15 * p + (1 + p) * std::cos(2 * M_PI * 2 * k / T - 0.6 * (points - 1 - p)); },
      [&](int p, int k) { return 60.0 + (p == points - 1 ? 4.0 * std::cos(2 * M_PI * 2 * k / T) : 0.0); });
}

TEST(TrackTargetsTest, PhaseTargetsReadAPointsPhaseAgainstTheFlyCornerWeightedByTheSqrtOfItsAmplitude) {
  const Tracks t = TravellingWave(60);
  const int points = 4, bins = 3;
  const std::vector<float> y = TrackTargets(t, 0, 30, cv::Rect(0, 0, 128, 128), 128, false, bins);
  ASSERT_EQ(y.size(), static_cast<size_t>(TrackTargetCount(points, bins)));
  // The amplitude and mean targets are those without phases.
  const std::vector<float> plain = TrackTargets(t, 0, 30, cv::Rect(0, 0, 128, 128), 128, false);
  for (size_t i = 0; i < plain.size(); ++i) EXPECT_EQ(y[i], plain[i]) << i;
  for (int p = 0; p < points; ++p) {
    // A cosine of amplitude a px reads a / 2 at its bin in units of half the frame (2 / 128 per px).
    const double amplitude = (1 + p) * 2.0 / 128 / 2, lag = -0.6 * (points - 1 - p);
    EXPECT_NEAR(y[Phase(points, bins, p, 2, 0, 0)], std::sqrt(amplitude) * std::cos(lag), 1e-4) << p;
    EXPECT_NEAR(y[Phase(points, bins, p, 2, 0, 1)], std::sqrt(amplitude) * std::sin(lag), 1e-4) << p;
  }
  // The reference itself: its v at phase 0; the other points' v do not move.
  EXPECT_NEAR(y[Phase(points, bins, 3, 2, 1, 0)], std::sqrt(4.0 * 2 / 128 / 2), 1e-4);
  EXPECT_NEAR(y[Phase(points, bins, 3, 2, 1, 1)], 0.0, 1e-6);
  EXPECT_EQ(y[Phase(points, bins, 0, 2, 1, 0)], 0.0f);
  EXPECT_EQ(y[Phase(points, bins, 0, 2, 1, 1)], 0.0f);
}

TEST(TrackTargetsTest, PhaseTargetsDoNotDependOnWhenTheWindowStartsAndFlipWithTheHorizontalMotion) {
  const Tracks t = TravellingWave(60);
  const int points = 4, bins = 2;
  const cv::Rect whole(0, 0, 128, 128);
  const std::vector<float> a = TrackTargets(t, 0, 30, whole, 128, false, bins);
  const std::vector<float> b = TrackTargets(t, 11, 30, whole, 128, false, bins);  // 11 frames later, not a whole period
  const std::vector<float> m = TrackTargets(t, 11, 30, whole, 128, true, bins);
  for (int p = 0; p < points; ++p)
    for (int part = 0; part < 2; ++part) {
      const int u = Phase(points, bins, p, 2, 0, part), v = Phase(points, bins, p, 2, 1, part);
      EXPECT_NEAR(b[u], a[u], 1e-5) << p;
      EXPECT_NEAR(m[u], -a[u], 1e-5) << p;  // mirrored: u and with it its phasor change sign
      EXPECT_NEAR(m[v], a[v], 1e-5) << p;
    }
  EXPECT_THROW(TrackTargets(t, 0, 30, whole, 128, false, kTrackBins + 1), std::invalid_argument);
  EXPECT_THROW(TrackTargets(t, 0, 30, whole, 128, false, -1), std::invalid_argument);
}

TEST(TrackTargetsTest, ScaleStandardisesEachTargetAndLeavesAConstantOneAtStdOne) {
  const TargetScale s = ScaleOf({{1, 5, 2}, {3, 5, 4}, {5, 5, 9}});
  ASSERT_EQ(s.mean.size(), 3u);
  EXPECT_FLOAT_EQ(s.mean[0], 3);
  EXPECT_NEAR(s.std[0], std::sqrt(8.0 / 3), 1e-6);
  EXPECT_FLOAT_EQ(s.mean[1], 5);
  EXPECT_FLOAT_EQ(s.std[1], 1);
  EXPECT_FLOAT_EQ(s.mean[2], 5);
}

// Gives `t` positions: point p at world(p, k) = (x, y, z) [m].
template <typename W>
Tracks WithWorld(Tracks t, W world) {
  for (int k = 0; k < t.frames; ++k)
    for (int p = 0; p < t.points(); ++p) {
      const std::array<double, 3> w = world(p, k);
      for (double v : w) t.world.push_back(static_cast<float>(v));
    }
  return t;
}

// Index of a point's world target: c (0 x, 1 y, 2 z) mean; c's bin j.
int WorldMean(int p, int c) { return p * kWorldTargetsPerPoint + c; }
int WorldBin(int p, int c, int j) { return p * kWorldTargetsPerPoint + 3 + c * kTrackBins + j - 1; }

TEST(WorldTrackTargetsTest, ASwingAcrossTheWindReadsHalfItsAmplitudeInMetresWhereverTheCameraWas) {
  // Point 1 (the fly edge) swings 0.2 m across the wind at bin 3 of a 30-frame window, 2.5 m
  // downwind and 1 m up; point 0 hangs still at the hoist. The image tracks are a still point:
  // what the camera showed does not enter.
  const int T = 30;
  const Tracks t = WithWorld(MakeTracks(1, 2, 128, 40, [](int, int) { return 64.0; }, [](int, int) { return 64.0; }),
                             [&](int p, int k) {
                               return p == 0 ? std::array<double, 3>{0.0, 0.0, 1.0}
                                             : std::array<double, 3>{2.5, 0.2 * std::sin(2 * M_PI * 3 * k / T), 1.0};
                             });
  const std::vector<float> y = WorldTrackTargets(t, 10, T, false);
  ASSERT_EQ(y.size(), 2u * kWorldTargetsPerPoint);
  EXPECT_NEAR(y[WorldMean(1, 0)], 2.5, 1e-6);
  EXPECT_NEAR(y[WorldMean(1, 1)], 0.0, 1e-6);
  EXPECT_NEAR(y[WorldMean(1, 2)], 1.0, 1e-6);
  EXPECT_NEAR(y[WorldBin(1, 1, 3)], std::log(1e-4 + 0.1), 1e-4);
  EXPECT_NEAR(y[WorldBin(1, 1, 2)], std::log(1e-4 + 0.05), 1e-4);  // the Hann window's neighbours: a quarter
  EXPECT_LT(y[WorldBin(1, 1, 5)], std::log(2e-4));
  for (int j = 1; j <= kTrackBins; ++j) {
    EXPECT_NEAR(y[WorldBin(1, 0, j)], std::log(1e-4), 1e-6) << j;  // no motion along the wind or up
    EXPECT_NEAR(y[WorldBin(1, 2, j)], std::log(1e-4), 1e-6) << j;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(y[WorldBin(0, c, j)], std::log(1e-4), 1e-6) << j;
  }
}

TEST(WorldTrackTargetsTest, AMirroredSampleIsTheMirroredSceneYNegatedAndTheMotionKept) {
  const Tracks t = WithWorld(MakeTracks(2, 2, 128, 40, [](int, int) { return 10.0; }, [](int, int) { return 10.0; }),
                             [](int p, int k) {
                               return std::array<double, 3>{1.0 + 0.5 * p + 0.03 * std::cos(0.5 * k),
                                                            0.1 * p + 0.2 * std::sin(0.9 * k + p), 2.0 - 0.3 * p};
                             });
  const std::vector<float> a = WorldTrackTargets(t, 3, 30, false), b = WorldTrackTargets(t, 3, 30, true);
  for (int p = 0; p < 4; ++p) {
    EXPECT_NEAR(b[WorldMean(p, 0)], a[WorldMean(p, 0)], 1e-6);
    EXPECT_NEAR(b[WorldMean(p, 1)], -a[WorldMean(p, 1)], 1e-6);
    EXPECT_NE(a[WorldMean(p, 1)], 0.0f);
    EXPECT_NEAR(b[WorldMean(p, 2)], a[WorldMean(p, 2)], 1e-6);
    for (int c = 0; c < 3; ++c)
      for (int j = 1; j <= kTrackBins; ++j) EXPECT_NEAR(b[WorldBin(p, c, j)], a[WorldBin(p, c, j)], 1e-5);
  }
  // Tracks without positions, or a window past them, are refused.
  Tracks bare = t;
  bare.world.clear();
  EXPECT_THROW(WorldTrackTargets(bare, 0, 30, false), std::invalid_argument);
  EXPECT_THROW(WorldTrackTargets(t, 11, 30, false), std::invalid_argument);
}

class TracksFileTest : public ::testing::Test {
 protected:
  void SetUp() override { path_ = fs::temp_directory_path() / ("cw_tracks_" + std::to_string(::getpid()) + ".json"); }
  void TearDown() override { fs::remove(path_); }
  void Write(const nlohmann::json& j) { std::ofstream(path_) << j.dump(); }
  fs::path path_;
};

TEST_F(TracksFileTest, ReadsTheGridAndFramesMakeDatasetWrites) {
  Write({{"format", "clothwind-tracks"}, {"version", 1}, {"grid", {1, 2}}, {"width", 128}, {"height", 128},
         {"vertices", {3, 7}}, {"xy", {{1.5, 2.5, 3.5, 4.5}, {1.25, 2.25, 3.25, 4.25}, {0, 0, 0, 0}}}});
  const Tracks t = ReadTracks(path_);
  EXPECT_EQ(t.points(), 2);
  EXPECT_EQ(t.frames, 3);
  EXPECT_EQ(t.width, 128);
  ASSERT_EQ(t.xy.size(), 12u);
  EXPECT_FLOAT_EQ(t.xy[4], 1.25);  // frame 1, point 0, x
  EXPECT_FLOAT_EQ(t.xy[7], 4.25);  // frame 1, point 1, y
  EXPECT_TRUE(t.world.empty());     // a file from before positions were stored
  Write({{"format", "clothwind-tracks"}, {"version", 1}, {"grid", {1, 2}}, {"width", 128}, {"height", 128},
         {"xy", {{1.5, 2.5, 3.5, 4.5}, {1.25, 2.25, 3.25, 4.25}}},
         {"world", {{0.5, 0, 1, 2.5, 0.25, 1}, {0.5, 0, 1, 2.5, -0.25, 1.5}}}});
  const Tracks w = ReadTracks(path_);
  ASSERT_EQ(w.world.size(), 12u);
  EXPECT_FLOAT_EQ(w.world[10], -0.25);  // frame 1, point 1, y
  EXPECT_FLOAT_EQ(w.world[11], 1.5);    // frame 1, point 1, z
}

TEST_F(TracksFileTest, ErrorsNameTheFileAndTheField) {
  auto message = [&](const nlohmann::json& j) {
    Write(j);
    try {
      ReadTracks(path_);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const nlohmann::json good = {{"format", "clothwind-tracks"}, {"version", 1}, {"grid", {1, 2}},
                               {"width", 8}, {"height", 8}, {"xy", {{1, 2, 3, 4}}}};
  nlohmann::json j = good;
  j["xy"][0].erase(3);
  std::string m = message(j);
  EXPECT_NE(m.find(path_.string()), std::string::npos) << m;
  EXPECT_NE(m.find("xy[0]"), std::string::npos) << m;
  j = good;
  j.erase("width");
  EXPECT_NE(message(j).find("'width'"), std::string::npos);
  j = good;
  j["format"] = "clothwind-dataset";
  EXPECT_NE(message(j).find("'format'"), std::string::npos);
  j = good;
  j["world"] = {{0, 0, 1, 2, 0}};  // 5 of 6 coordinates
  EXPECT_NE(message(j).find("'world[0]'"), std::string::npos);
  j["world"] = {{0, 0, 1, 2, 0, 1}, {0, 0, 1, 2, 0, 1}};  // 2 frames of 1
  EXPECT_NE(message(j).find("'world'"), std::string::npos);
  // Each of these escaped as nlohmann's own error, naming neither the file nor the field.
  m = message(nlohmann::json::array({1, 2}));
  EXPECT_NE(m.find(path_.string() + ": expected a JSON object"), std::string::npos) << m;
  j = good;
  j["version"] = "1";
  EXPECT_NE(message(j).find("'version' must be the integer 1"), std::string::npos) << message(j);
  j = good;
  j["grid"] = {8.5, 6};  // was read as 8
  EXPECT_NE(message(j).find("'grid[0]' must be a positive integer, got 8.5"), std::string::npos) << message(j);
  j = good;
  j["height"] = 4294967304;  // wrapped to 8
  EXPECT_NE(message(j).find("'height' must be a positive integer"), std::string::npos) << message(j);
  // A coordinate beyond a float became inf, and training ran on NaN losses to its end (exit 0).
  j = good;
  j["xy"][0][3] = 1e300;
  EXPECT_NE(message(j).find("'xy[0][3]' must be a finite number"), std::string::npos) << message(j);
  j = good;
  j["xy"][0][1] = "2";
  EXPECT_NE(message(j).find("'xy[0][1]' must be a finite number"), std::string::npos) << message(j);
  j = good;
  j["world"] = {{0, 0, 1, 2, -1e39, 1}};
  EXPECT_NE(message(j).find("'world[0][4]' must be a finite number"), std::string::npos) << message(j);
  // 65536 x 65536 points wrapped points() to 0, which failed inside libtorch naming no file.
  j = good;
  j["grid"] = {65536, 65536};
  EXPECT_NE(message(j).find("'grid' must hold at most 2^20 points"), std::string::npos) << message(j);
}

}  // namespace
}  // namespace clothwind::learn
