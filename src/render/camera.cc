#include "render/camera.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>

namespace clothwind::render {

PinholeCamera PinholeCamera::LookAt(const Eigen::Vector3d& position,
                                    const Eigen::Vector3d& target, double fov_deg, int width,
                                    int height) {
  PinholeCamera c;
  c.position = position;
  c.forward = (target - position).normalized();
  Eigen::Vector3d right = c.forward.cross(Eigen::Vector3d::UnitZ());
  if (!(right.norm() > 1e-9))
    throw std::invalid_argument("PinholeCamera::LookAt: viewing direction is vertical");
  c.right = right.normalized();
  c.down = c.forward.cross(c.right);
  c.width = width;
  c.height = height;
  c.focal_px = 0.5 * width / std::tan(0.5 * fov_deg * M_PI / 180.0);
  c.cx = 0.5 * width;
  c.cy = 0.5 * height;
  return c;
}

bool PinholeCamera::Project(const Eigen::Vector3d& point, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d d = point - position;
  const double z = d.dot(forward);
  if (z <= 1e-9) return false;
  *pixel = Eigen::Vector2d(cx + focal_px * d.dot(right) / z, cy + focal_px * d.dot(down) / z);
  return true;
}

Eigen::Vector3d PinholeCamera::RayDirection(double x, double y) const {
  return (forward + ((x - cx) / focal_px) * right + ((y - cy) / focal_px) * down).normalized();
}

Eigen::Matrix3d PinholeCamera::K() const {
  Eigen::Matrix3d k;
  k << focal_px, 0, cx, 0, focal_px, cy, 0, 0, 1;
  return k;
}

Eigen::Vector3d MeshCentre(const RenderParams& p) {
  if (p.has_look_at) return Eigen::Vector3d(p.look_at[0], p.look_at[1], p.look_at[2]);
  const double w = p.mesh_width, h = p.MeshRestHeight();
  if (p.scene == SceneKind::kFlag) return Eigen::Vector3d(0.5 * w, 0.0, p.mesh_height + 0.5 * h);
  return Eigen::Vector3d(0.0, 0.5 * w, p.mesh_height + 0.5 * h);
}

PinholeCamera PlaceCamera(const RenderParams& p) {
  const Eigen::Vector3d target = MeshCentre(p);
  const Eigen::Vector3d base = p.scene == SceneKind::kFlag ? Eigen::Vector3d(0, -1, 0)
                                                           : Eigen::Vector3d(-1, 0, 0);
  const Eigen::Vector3d offset =
      Eigen::AngleAxisd(p.camera_angle_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * base *
      p.camera_radius;
  const Eigen::Vector3d position(target.x() + offset.x(), target.y() + offset.y(),
                                 p.camera_height);
  return PinholeCamera::LookAt(position, target, p.camera_fov_deg, p.width, p.height);
}

}  // namespace clothwind::render
