#include "render/camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace clothwind::render {
namespace {

TEST(PinholeCamera, KnownPointLandsOnKnownPixel) {
  // Looking along +y from the origin with a 90 degree field of view: f = 150 px.
  const PinholeCamera c = PinholeCamera::LookAt(Eigen::Vector3d::Zero(),
                                                Eigen::Vector3d(0, 10, 0), 90.0, 300, 300);
  EXPECT_NEAR(c.focal_px, 150.0, 1e-9);
  Eigen::Vector2d px;
  ASSERT_TRUE(c.Project(Eigen::Vector3d(1, 10, 0), &px));
  EXPECT_NEAR(px.x(), 165.0, 1e-9);  // +x is to the right
  EXPECT_NEAR(px.y(), 150.0, 1e-9);
  ASSERT_TRUE(c.Project(Eigen::Vector3d(0, 10, -2), &px));
  EXPECT_NEAR(px.x(), 150.0, 1e-9);
  EXPECT_NEAR(px.y(), 180.0, 1e-9);  // below the axis is further down the image
  EXPECT_FALSE(c.Project(Eigen::Vector3d(0, -1, 0), &px));  // behind
  const Eigen::Matrix3d K = c.K();
  EXPECT_NEAR(K(0, 0), 150.0, 1e-9);
  EXPECT_NEAR(K(0, 2), 150.0, 1e-9);
  EXPECT_NEAR(K(1, 2), 150.0, 1e-9);
}

TEST(PinholeCamera, RayThroughProjectionHitsThePoint) {
  const PinholeCamera c = PinholeCamera::LookAt(Eigen::Vector3d(1, -4, 1.5),
                                                Eigen::Vector3d(1.5, 0, 5.6), 45.0, 300, 300);
  const Eigen::Vector3d p(2.3, 0.4, 6.1);
  Eigen::Vector2d px;
  ASSERT_TRUE(c.Project(p, &px));
  const Eigen::Vector3d d = c.RayDirection(px.x(), px.y());
  const Eigen::Vector3d to_p = (p - c.position).normalized();
  EXPECT_NEAR((d - to_p).norm(), 0.0, 1e-12);
}

TEST(PlaceCamera, FlagCentreProjectsToImageCentreAndTableTwoPlacementHolds) {
  RenderParams p;
  p.camera_height = 1.3;
  p.camera_radius = 5.2;
  p.camera_angle_deg = 12.0;
  const PinholeCamera c = PlaceCamera(p);
  const Eigen::Vector3d centre = MeshCentre(p);
  EXPECT_NEAR(centre.z(), 4.6 + 1.0, 1e-12);  // 2 m flag whose hoist starts at 4.6 m
  Eigen::Vector2d px;
  ASSERT_TRUE(c.Project(centre, &px));
  EXPECT_NEAR(px.x(), 150.0, 1e-9);
  EXPECT_NEAR(px.y(), 150.0, 1e-9);
  EXPECT_NEAR(c.position.z(), 1.3, 1e-12);
  EXPECT_NEAR(std::hypot(c.position.x() - centre.x(), c.position.y() - centre.y()), 5.2, 1e-9);
  // The angle is measured from the side-on view (camera on -y).
  const double angle = std::atan2(c.position.x() - centre.x(), -(c.position.y() - centre.y()));
  EXPECT_NEAR(angle * 180.0 / M_PI, 12.0, 1e-9);  // counter-clockwise: towards +x (downwind)
  EXPECT_NEAR(c.focal_px, 150.0 / std::tan(22.5 * M_PI / 180.0), 1e-9);
}

TEST(PlaceCamera, WindBlowsLeftToRightAndUpIsUp) {
  RenderParams p;
  p.camera_angle_deg = 0.0;
  const PinholeCamera c = PlaceCamera(p);
  Eigen::Vector2d a, b, top;
  const Eigen::Vector3d centre = MeshCentre(p);
  ASSERT_TRUE(c.Project(centre, &a));
  ASSERT_TRUE(c.Project(centre + Eigen::Vector3d(1, 0, 0), &b));
  ASSERT_TRUE(c.Project(centre + Eigen::Vector3d(0, 0, 1), &top));
  EXPECT_GT(b.x(), a.x() + 10);  // downwind is to the right
  EXPECT_LT(top.y(), a.y() - 10);  // up is up
  // The pole (x = 0) is left of the flag's centre.
  Eigen::Vector2d pole;
  ASSERT_TRUE(c.Project(Eigen::Vector3d(0, 0, centre.z()), &pole));
  EXPECT_LT(pole.x(), a.x());
}

TEST(PlaceCamera, ClothIsSeenFaceOn) {
  RenderParams p;
  p.scene = SceneKind::kCloth;
  p.mesh_height = 2.0;
  p.mesh_width = 1.0;
  p.mesh_aspect_ratio = 1.0;
  p.camera_radius = 1.5;
  p.camera_height = 1.0;
  p.camera_angle_deg = 0.0;
  const PinholeCamera c = PlaceCamera(p);
  const Eigen::Vector3d centre = MeshCentre(p);
  EXPECT_NEAR(centre.y(), 0.5, 1e-12);
  EXPECT_NEAR(centre.z(), 2.5, 1e-12);
  EXPECT_NEAR(c.position.x(), -1.5, 1e-9);  // in front of the y-z plane, on -x
  EXPECT_NEAR(c.position.y(), 0.5, 1e-9);
  Eigen::Vector2d px;
  ASSERT_TRUE(c.Project(centre, &px));
  EXPECT_NEAR(px.x(), 150.0, 1e-9);
  EXPECT_NEAR(px.y(), 150.0, 1e-9);
}

TEST(FrameClip, HangingFlagStaysInTheFrame) {
  // A flag hanging down the pole (1 m/s: droop ~80 deg): the hoist from z = 0 to 2, the fly
  // end ~2.9 m lower, in the simulator's frame. Aimed at the flying rest centre its lower part
  // leaves the frame; framed from the clip, every vertex is in view and the box centre is the
  // image centre.
  Eigen::MatrixXd V(6, 3);
  V << 0, 0, 2, 0.3, 0, 0.5, 0.5, 0.1, -2.6, 0, 0, 0, 0.2, -0.1, -1.5, 0.4, 0, -0.8;
  RenderParams p;
  p.camera_height = 1.6;
  p.camera_radius = 5.0;
  auto all_in_view = [&](const RenderParams& q) {
    const PinholeCamera c = PlaceCamera(q);
    for (int i = 0; i < V.rows(); ++i) {
      Eigen::Vector2d px;
      const Eigen::Vector3d w = V.row(i).transpose() + Eigen::Vector3d(0, 0, q.mesh_height);
      if (!c.Project(w, &px) || px.x() < 0 || px.x() > q.width || px.y() < 0 || px.y() > q.height)
        return false;
    }
    return true;
  };
  EXPECT_FALSE(all_in_view(p));
  RenderParams framed = p;
  FrameClip({V, V * 0.9}, &framed);
  EXPECT_TRUE(all_in_view(framed));
  EXPECT_NEAR(framed.look_at[2], 4.6 - 0.3, 1e-12);  // (2 + -2.6) / 2 lifted by 4.6
  EXPECT_GT(framed.camera_fov_deg, p.camera_fov_deg);  // 4.6 m tall does not fit in 45 deg
  EXPECT_LT(framed.camera_fov_deg, 60.0);
  // A flying flag fits already: the field of view stays.
  Eigen::MatrixXd flying(4, 3);
  flying << 0, 0, 0, 0, 0, 2, 3, 0.3, 0.2, 3, -0.3, 1.9;
  RenderParams f = p;
  FrameClip({flying}, &f);
  EXPECT_DOUBLE_EQ(f.camera_fov_deg, p.camera_fov_deg);
  Eigen::Vector2d px;
  ASSERT_TRUE(PlaceCamera(framed).Project(Eigen::Vector3d(0.25, 0.0, 4.3), &px));
  EXPECT_NEAR(px.x(), 150.0, 1e-9);
  EXPECT_NEAR(px.y(), 150.0, 1e-9);
  // The aim survives label.json.
  const RenderParams back = RenderParamsFromJson(nlohmann::json::parse(ToJson(framed).dump()));
  EXPECT_TRUE(back.has_look_at);
  EXPECT_DOUBLE_EQ(back.look_at[0], framed.look_at[0]);
  EXPECT_DOUBLE_EQ(back.look_at[2], framed.look_at[2]);
  EXPECT_THROW(FrameClip({}, &framed), std::invalid_argument);
  // A frame wider than tall: the field of view is horizontal, so the hanging flag needs more of
  // it (the vertical tangent was taken for the horizontal one: the flag overflowed 400x200).
  RenderParams wide = p;
  wide.width = 400;
  wide.height = 200;
  FrameClip({V, V * 0.9}, &wide);
  EXPECT_TRUE(all_in_view(wide));
  EXPECT_GT(wide.camera_fov_deg, framed.camera_fov_deg);
}

// "Never narrows": a field of view past the widening's 120 deg cap stays (it was cut to 120).
TEST(FrameClip, AWideFieldOfViewStays) {
  Eigen::MatrixXd flying(4, 3);
  flying << 0, 0, 0, 0, 0, 2, 3, 0.3, 0.2, 3, -0.3, 1.9;
  RenderParams p;
  p.camera_fov_deg = 150.0;
  FrameClip({flying}, &p);
  EXPECT_EQ(p.camera_fov_deg, 150.0);
  // And the widening still stops at 120: a camera 0.2 m from a 3 m flag, level with it, would
  // need more.
  RenderParams near;
  near.camera_radius = 0.2;
  near.camera_height = near.mesh_height + 1.0;
  FrameClip({flying}, &near);
  EXPECT_EQ(near.camera_fov_deg, kFrameClipMaxFovDeg);
}

TEST(FrameClip, NonFiniteVerticesAreNamed) {
  Eigen::MatrixXd V(3, 3);
  V << 0, 0, 0, 0, 0, 2, 3, 0, 1;
  Eigen::MatrixXd bad = V;
  bad(2, 1) = std::numeric_limits<double>::quiet_NaN();
  RenderParams p;
  try {
    FrameClip({V, bad}, &p);
    FAIL() << "a NaN vertex was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("frame 1, vertex 2 has coordinate y = nan"), std::string::npos)
        << e.what();
  }
  bad(2, 1) = std::numeric_limits<double>::infinity();
  EXPECT_THROW(FrameClip({bad}, &p), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::render
