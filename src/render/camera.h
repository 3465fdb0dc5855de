#ifndef CLOTHWIND_RENDER_CAMERA_H_
#define CLOTHWIND_RENDER_CAMERA_H_

#include <Eigen/Core>

#include "render/render_params.h"

namespace clothwind::render {

// A pinhole camera without distortion.
//
// Image coordinates are continuous, x to the right and y down, with pixel (i, j) covering
// [i, i+1) x [j, j+1), so its centre is (i + 0.5, j + 0.5). Intrinsics:
//   fx = fy = (width / 2) / tan(fov / 2),  cx = width / 2,  cy = height / 2
// (300x300 with the default fov of 45 deg: f = 362.1 px, principal point (150, 150)).
// The camera frame is right (x), down (y), forward (z); world is z up (REP 103).
struct PinholeCamera {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // [m] world
  Eigen::Vector3d right = Eigen::Vector3d::UnitX();     // world direction of image +x
  Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();     // world direction of image +y
  Eigen::Vector3d forward = Eigen::Vector3d::UnitY();   // viewing direction
  double focal_px = 362.1;
  double cx = 150.0, cy = 150.0;
  int width = 300, height = 300;

  // Camera at `position` looking at `target`, world z up.
  // Inputs: position, target  [m] world, distinct and not vertically aligned; fov_deg  field of
  //   view across the width [deg]; width, height  image size [px].
  static PinholeCamera LookAt(const Eigen::Vector3d& position, const Eigen::Vector3d& target,
                              double fov_deg, int width, int height);

  // Projects a world point. Returns false if the point is not in front of the camera.
  // Outputs: pixel  continuous image coordinates [px].
  bool Project(const Eigen::Vector3d& point, Eigen::Vector2d* pixel) const;

  // Unit world direction of the ray through continuous image coordinates (x, y) [px].
  Eigen::Vector3d RayDirection(double x, double y) const;

  // 3x3 intrinsic matrix K.
  Eigen::Matrix3d K() const;
};

// The point the camera looks at: p.look_at when set (FrameClip), else the centre of the mesh at
// rest in world coordinates, for a flag flying downwind ((w/2, 0, mesh_height + h/2); the hoist
// is on the z axis and wind along +x) and for a hanging cloth ((0, w/2, mesh_height + h/2); it
// hangs in the y-z plane).
Eigen::Vector3d MeshCentre(const RenderParams& p);

// The camera of seed Table 2: at horizontal distance camera_radius from MeshCentre, at
// camera_height above the ground, looking at MeshCentre. camera_angle_deg = 0 is the side-on
// view of each scene (flag: from -y, so the wind blows left to right and the pole is on the
// left; cloth: from -x, facing the cloth), positive angles turn the camera counter-clockwise
// about the vertical through MeshCentre.
PinholeCamera PlaceCamera(const RenderParams& p);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_CAMERA_H_
