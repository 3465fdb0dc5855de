// The heading a camera's pose gives learn::FlyDirectionFromWind (fly_direction.h), for sdn_node's
// ~flag_flies wind with the pose from tf. Apart from fly_direction.h, which the GPU build
// (scripts/device-check) compiles without Eigen.
#ifndef CLOTHWIND_LEARN_CAMERA_HEADING_H_
#define CLOTHWIND_LEARN_CAMERA_HEADING_H_

#include <optional>

#include <Eigen/Core>

namespace clothwind::learn {

// The heading to give FlyDirectionFromWind for a camera that need not be level: that of the level
// camera whose picture's right points the same way across the ground, from the camera's
// orientation in the anemometer's frame (a tf2 lookup). Its picture's right is what a flag flies
// toward, so a camera pitched up or down keeps its heading and one mounted upside down gets the
// opposite one (the flag crosses its picture the other way); the optical axis alone said neither.
// Inputs:
//   camera_axes  3x3 rotation whose columns are the camera's optical-frame axes (REP 103's
//                "_optical" frames: x to the picture's right, y down it, z along the optical axis)
//                in the anemometer's frame, z up
// Returns the heading [rad] in [-pi, pi], counter-clockwise about +z from +x; nothing when the
// picture's right leans more than 45 deg out of the horizontal (a camera on its side sees a flag
// fly up or down its picture, which no side tells) or the rotation is not finite.
std::optional<double> EquivalentCameraHeading(const Eigen::Matrix3d& camera_axes);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_CAMERA_HEADING_H_
