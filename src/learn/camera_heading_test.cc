// EquivalentCameraHeading on camera poses whose way is known: level cameras, pitched, rolled, upside
// down, on their side, looking down, and static_transform_publisher's yaw-pitch-roll.
#include "learn/camera_heading.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "learn/fly_direction.h"

namespace clothwind::learn {
namespace {

// A level camera with the given heading: optical axis along it, picture's right 90 deg clockwise
// of it, picture's down along -z (REP 103 optical axes as the columns).
Eigen::Matrix3d LevelCamera(double heading) {
  Eigen::Matrix3d axes;
  axes.col(0) = Eigen::Vector3d(std::sin(heading), -std::cos(heading), 0);
  axes.col(2) = Eigen::Vector3d(std::cos(heading), std::sin(heading), 0);
  axes.col(1) = axes.col(2).cross(axes.col(0));
  return axes;
}

// The angle between two headings [rad], 0 .. pi.
double HeadingGap(double a, double b) { return std::abs(std::remainder(a - b, 2 * M_PI)); }

TEST(EquivalentCameraHeading, ALevelCameraHasItsOwnHeadingAndTheSameWaysAsTheParameter) {
  for (const double heading : {0.0, 0.4, M_PI / 2, 2.5, M_PI, -1.0, -M_PI / 2}) {
    const auto got = EquivalentCameraHeading(LevelCamera(heading));
    ASSERT_TRUE(got) << heading;
    EXPECT_NEAR(HeadingGap(*got, heading), 0, 1e-12) << heading;
    EXPECT_LE(std::abs(*got), M_PI + 1e-12);
    for (const double wind : {0.1, 1.3, 2.9, -2.2}) {
      EXPECT_EQ(FlyDirectionFromWind(wind, *got, 0.2), FlyDirectionFromWind(wind, heading, 0.2)) << heading << " " << wind;
    }
  }
}

TEST(EquivalentCameraHeading, PitchKeepsTheHeadingAndUpsideDownReversesTheWay) {
  const double north = M_PI / 2;
  const Eigen::Matrix3d level = LevelCamera(north);
  // Pitched up 35 deg or down 20 deg (about the picture's right), rolled 30 deg (about the axis).
  for (const Eigen::Matrix3d& camera :
       {Eigen::Matrix3d(level * Eigen::AngleAxisd(0.61, Eigen::Vector3d::UnitX())),
        Eigen::Matrix3d(level * Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitX())),
        Eigen::Matrix3d(level * Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()))}) {
    const auto got = EquivalentCameraHeading(camera);
    ASSERT_TRUE(got);
    EXPECT_NEAR(HeadingGap(*got, north), 0, 1e-9);
  }
  // Upside down (rolled 180 deg): the air moving east, to a level camera's right, crosses this
  // camera's picture to its left.
  const auto upside_down = EquivalentCameraHeading(level * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  ASSERT_TRUE(upside_down);
  EXPECT_NEAR(HeadingGap(*upside_down, -north), 0, 1e-9);
  EXPECT_EQ(FlyDirectionFromWind(0.0, north, 0.2), FlyDirection::kRight);
  EXPECT_EQ(FlyDirectionFromWind(0.0, *upside_down, 0.2), FlyDirection::kLeft);
  // Looking straight down with the picture's right to the east: as a level camera facing north.
  Eigen::Matrix3d down;
  down.col(0) = Eigen::Vector3d(1, 0, 0);
  down.col(2) = Eigen::Vector3d(0, 0, -1);
  down.col(1) = down.col(2).cross(down.col(0));
  ASSERT_TRUE(EquivalentCameraHeading(down));
  EXPECT_NEAR(HeadingGap(*EquivalentCameraHeading(down), north), 0, 1e-12);
}

TEST(EquivalentCameraHeading, ACameraOnItsSideOrANonFiniteRotationHasNone) {
  const Eigen::Matrix3d level = LevelCamera(1.0);
  EXPECT_TRUE(EquivalentCameraHeading(level * Eigen::AngleAxisd(0.75, Eigen::Vector3d::UnitZ())));   // 43 deg
  EXPECT_FALSE(EquivalentCameraHeading(level * Eigen::AngleAxisd(0.82, Eigen::Vector3d::UnitZ())));  // 47 deg
  EXPECT_FALSE(EquivalentCameraHeading(level * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())));
  Eigen::Matrix3d bad = level;
  bad(0, 0) = std::nan("");
  EXPECT_FALSE(EquivalentCameraHeading(bad));
}

TEST(EquivalentCameraHeading, ReadsAStaticTransformPublishersYawPitchRoll) {
  // static_transform_publisher's `x y z yaw pitch roll` is the rotation Rz(yaw) Ry(pitch) Rx(roll):
  // `0 0 0 0 0 -1.5707963` puts the optical axis along +y and the picture's right along +x, a
  // level camera facing +y.
  const Eigen::Matrix3d camera = (Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(-1.5707963, Eigen::Vector3d::UnitX()))
                                     .toRotationMatrix();
  EXPECT_NEAR((camera.col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 0, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(camera));
  EXPECT_NEAR(*EquivalentCameraHeading(camera), M_PI / 2, 1e-6);
  // docs/sdn.md's example, `3 0 0 -1.5707963 0 -1.5707963 anemometer ...`: a level camera facing the
  // instrument's north mark (+x), its picture's right along -y: heading 0.
  const Eigen::Matrix3d example = (Eigen::AngleAxisd(-1.5707963, Eigen::Vector3d::UnitZ()) *
                                   Eigen::AngleAxisd(-1.5707963, Eigen::Vector3d::UnitX()))
                                      .toRotationMatrix();
  EXPECT_NEAR((example.col(2) - Eigen::Vector3d(1, 0, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR((example.col(0) - Eigen::Vector3d(0, -1, 0)).norm(), 0, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(example));
  EXPECT_NEAR(*EquivalentCameraHeading(example), 0, 1e-6);
  // Its camera (`... 2.6179939 0 1.5707963 ...`): facing 60 deg, upside down, its picture's right
  // toward 150 deg as a level camera facing -120 deg sees it. The inverse transform (frames
  // swapped in the lookup) reads -90 deg, so a wind toward 60 deg is end-on only read right.
  const Eigen::Matrix3d upside_down = (Eigen::AngleAxisd(2.6179939, Eigen::Vector3d::UnitZ()) *
                                       Eigen::AngleAxisd(1.5707963, Eigen::Vector3d::UnitX()))
                                          .toRotationMatrix();
  EXPECT_NEAR((upside_down.col(2) - Eigen::Vector3d(std::cos(M_PI / 3), std::sin(M_PI / 3), 0)).norm(), 0, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(upside_down));
  EXPECT_NEAR(*EquivalentCameraHeading(upside_down), -2 * M_PI / 3, 1e-6);
  ASSERT_TRUE(EquivalentCameraHeading(upside_down.transpose()));
  EXPECT_NEAR(*EquivalentCameraHeading(upside_down.transpose()), -M_PI / 2, 1e-6);
  EXPECT_EQ(FlyDirectionFromWind(M_PI / 3, *EquivalentCameraHeading(upside_down), 0.35), std::nullopt);
  EXPECT_EQ(FlyDirectionFromWind(0.0, *EquivalentCameraHeading(upside_down), 0.35), FlyDirection::kLeft);
}

}  // namespace
}  // namespace clothwind::learn
