#include "learn/camera_heading.h"

#include <cmath>

namespace clothwind::learn {

std::optional<double> EquivalentCameraHeading(const Eigen::Matrix3d& camera_axes) {
  if (!camera_axes.allFinite()) return std::nullopt;
  const Eigen::Vector3d right = camera_axes.col(0);
  const double across_ground = std::hypot(right.x(), right.y());
  // 45 deg: beyond it the flag moves more up or down the picture than across it.
  if (!(across_ground > std::abs(right.z()))) return std::nullopt;
  // A level camera's picture's right is its heading turned 90 deg clockwise; undo that turn.
  return std::remainder(std::atan2(right.y(), right.x()) + M_PI / 2, 2 * M_PI);
}

}  // namespace clothwind::learn
