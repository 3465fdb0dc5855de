#include "data/clip_tracks.h"

#include <cmath>

#include <gtest/gtest.h>

namespace clothwind::data {
namespace {

// A flat 3 m x 2 m flag flying along +x in the x-z plane (simulator frame: hoist on the z axis),
// on an n_u x n_v grid of vertices, moved by `step` [m] along +x each frame.
ClothAnimation FlatFlag(int n_u, int n_v, int frames, double step) {
  ClothAnimation a;
  a.frame_time = 0.04;
  a.UV.resize(n_u * n_v, 2);
  for (int i = 0; i < n_u; ++i)
    for (int j = 0; j < n_v; ++j) a.UV.row(i * n_v + j) << i / (n_u - 1.0), j / (n_v - 1.0);
  a.F.resize(0, 3);
  for (int k = 0; k < frames; ++k) {
    ClothFrame f;
    f.V.resize(a.UV.rows(), 3);
    for (int v = 0; v < a.UV.rows(); ++v) f.V.row(v) << 3.0 * a.UV(v, 0) + k * step, 0.0, 2.0 * a.UV(v, 1);
    a.frames.push_back(f);
  }
  return a;
}

// A level, side-on camera (from -y, at the flag's centre height) `radius` m from the flag's rest centre.
render::RenderParams SideOn(double radius) {
  render::RenderParams p;
  p.scene = render::SceneKind::kFlag;
  p.camera_angle_deg = 0;
  p.camera_radius = radius;
  p.camera_height = p.mesh_height + 0.5 * p.mesh_width / p.mesh_aspect_ratio;
  p.width = p.height = 128;
  p.fps = 25;
  return p;
}

TEST(ClipTracksTest, GridVerticesAreTheMaterialPointsOffTheHoistToTheFlyEdge) {
  const ClothAnimation a = FlatFlag(9, 7, 1, 0.0);
  const TrackGrid grid{4, 3};
  const std::vector<int> v = GridVertices(a.UV, grid);
  ASSERT_EQ(v.size(), 12u);
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 3; ++row) {
      EXPECT_DOUBLE_EQ(a.UV(v[col * 3 + row], 0), (col + 1) / 4.0) << col << "," << row;
      EXPECT_DOUBLE_EQ(a.UV(v[col * 3 + row], 1), row / 2.0) << col << "," << row;
    }
  }
  // The last point is the fly edge's top corner.
  EXPECT_DOUBLE_EQ(a.UV(v.back(), 0), 1.0);
  EXPECT_DOUBLE_EQ(a.UV(v.back(), 1), 1.0);
}

TEST(ClipTracksTest, ALevelSideOnCameraSeesThePlaneOfTheFlagAtFocalLengthOverDistance) {
  // The flag's plane lies `radius` in front of a side-on camera at its centre: a point (x, 0, z)
  // appears at (cx + f (x - 1.5) / r, cy - f (z - 1) / r), and moving it along x moves it right.
  const double radius = 5.0, step = 0.1;
  const render::RenderParams p = SideOn(radius);
  const TrackGrid grid{2, 3};  // u = 0.5, 1; v = 0, 0.5, 1: point 1 is the flag's centre
  const ClothAnimation a = FlatFlag(9, 7, 4, step);
  const ClipTracks t = ProjectTracks(a, p, grid, 4);
  ASSERT_EQ(t.frames(), 4);
  ASSERT_EQ(t.xy.cols(), 12);
  EXPECT_EQ(t.width, 128);
  const double f = 64.0 / std::tan(M_PI / 8);  // 45 deg across 128 px
  for (int k = 0; k < 4; ++k) {
    for (int point = 0; point < 6; ++point) {
      const double x = 3.0 * a.UV(t.vertices[point], 0) + k * step, z = 2.0 * a.UV(t.vertices[point], 1);
      EXPECT_NEAR(t.xy(k, 2 * point), 64.0 + f * (x - 1.5) / radius, 1e-3) << k << " " << point;
      EXPECT_NEAR(t.xy(k, 2 * point + 1), 64.0 - f * (z - 1.0) / radius, 1e-3) << k << " " << point;
    }
  }
  EXPECT_NEAR(t.xy(0, 2), 64.0, 1e-4);  // the rest centre is the image centre
  EXPECT_NEAR(t.xy(0, 3), 64.0, 1e-4);
}

TEST(ClipTracksTest, FramesBetweenAnimationFramesAreInterpolatedAsTheRendererDrawsThem) {
  // At 50 fps on an animation of 25 fps, odd frames lie halfway between two simulated ones.
  render::RenderParams p = SideOn(5.0);
  p.fps = 50;
  const ClipTracks t = ProjectTracks(FlatFlag(9, 7, 3, 0.2), p, TrackGrid{2, 2}, 5);
  for (int i = 0; i < t.xy.cols(); ++i) EXPECT_NEAR(t.xy(1, i), 0.5 * (t.xy(0, i) + t.xy(2, i)), 1e-3);
  // The flag moves linearly, so the midpoint alone holds for any linear time mapping: frame 2 at
  // 50 fps (t = 0.04 s) must also be frame 1 at 25 fps, and frame 4 frame 2.
  render::RenderParams p25 = p;
  p25.fps = 25;
  const ClipTracks t25 = ProjectTracks(FlatFlag(9, 7, 3, 0.2), p25, TrackGrid{2, 2}, 3);
  for (int i = 0; i < t.xy.cols(); ++i) {
    EXPECT_NEAR(t.xy(2, i), t25.xy(1, i), 1e-6);
    EXPECT_NEAR(t.xy(4, i), t25.xy(2, i), 1e-6);
  }
  EXPECT_GT(std::abs(t.xy(2, 0) - t.xy(0, 0)), 1.0);  // the points move between those frames
  // At 100 fps a frame a quarter of the way: three quarters of the earlier simulated frame (at
  // the midpoint alone, the two frames' weights swapped gave the same blend).
  render::RenderParams p100 = p;
  p100.fps = 100;
  const ClipTracks t100 = ProjectTracks(FlatFlag(9, 7, 3, 0.2), p100, TrackGrid{2, 2}, 5);
  for (int i = 0; i < t100.xy.cols(); ++i)
    EXPECT_NEAR(t100.xy(1, i), 0.75 * t100.xy(0, i) + 0.25 * t100.xy(4, i), 1e-3);
}

TEST(ClipTracksTest, APointBehindTheCameraIsAnError) {
  const render::RenderParams p = SideOn(5.0);
  ClothAnimation a = FlatFlag(5, 5, 1, 0.0);
  a.frames[0].V.col(1).array() -= 20.0;  // the whole flag 15 m behind the camera
  EXPECT_THROW(ProjectTracks(a, p, TrackGrid{2, 2}, 1), std::runtime_error);
}

TEST(ClipTracksTest, JsonHoldsTheGridAndEveryFramesPixelsToAHundredthOfAPixel) {
  // Frames wider than high: the readers (scripts/track-oracle, plot-tracks) scale by these two,
  // and a square frame hid them swapped.
  render::RenderParams wide = SideOn(5.0);
  wide.width = 160;
  wide.height = 96;
  const nlohmann::json jw = TracksJson(ProjectTracks(FlatFlag(9, 7, 2, 0.1), wide, TrackGrid{4, 3}, 2));
  EXPECT_EQ(jw.at("width"), 160);
  EXPECT_EQ(jw.at("height"), 96);
  const ClipTracks t = ProjectTracks(FlatFlag(9, 7, 2, 0.1), SideOn(5.0), TrackGrid{4, 3}, 2);
  const nlohmann::json j = TracksJson(t);
  EXPECT_EQ(j.at("format"), "clothwind-tracks");
  EXPECT_EQ(j.at("grid"), nlohmann::json({4, 3}));
  EXPECT_EQ(j.at("vertices").get<std::vector<int>>(), t.vertices);
  ASSERT_EQ(j.at("xy").size(), 2u);
  for (int k = 0; k < 2; ++k) {
    ASSERT_EQ(j["xy"][k].size(), 24u);
    for (int i = 0; i < 24; ++i) EXPECT_NEAR(j["xy"][k][i].get<double>(), t.xy(k, i), 0.005 + 1e-6);
  }
}

TEST(ClipTracksTest, WorldHoldsTheGridVerticesPositionsUnliftedAndJsonKeepsThemToATenthOfAMillimetre) {
  const ClothAnimation a = FlatFlag(9, 7, 3, 0.1234567);
  const ClipTracks t = ProjectTracks(a, SideOn(5.0), TrackGrid{4, 3}, 3);
  ASSERT_EQ(t.world.rows(), 3);
  ASSERT_EQ(t.world.cols(), 3 * 12);
  for (int k = 0; k < 3; ++k)
    for (int p = 0; p < 12; ++p)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(t.world(k, 3 * p + c), a.frames[k].V(t.vertices[p], c), 1e-6);
  const nlohmann::json j = TracksJson(t);
  ASSERT_EQ(j.at("world").size(), 3u);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 36; ++i) EXPECT_NEAR(j["world"][k][i].get<double>(), t.world(k, i), 0.5e-4 + 1e-6);
  // Tracks without positions write none.
  ClipTracks bare = t;
  bare.world.resize(0, 0);
  EXPECT_FALSE(TracksJson(bare).contains("world"));
}

TEST(ClipTracksTest, GridTextIsParsedOrRefusedByName) {
  const TrackGrid g = ParseTrackGrid("--tracks", "8x6");
  EXPECT_EQ(g.cols, 8);
  EXPECT_EQ(g.rows, 6);
  for (const char* bad : {"8", "8x", "x6", "8x1", "0x6", "8x6x2", "8 x6", "a x b"}) {
    try {
      ParseTrackGrid("--tracks", bad);
      ADD_FAILURE() << bad;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("--tracks"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace clothwind::data
