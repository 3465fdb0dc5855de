#include "render/lighting.h"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>

namespace clothwind::render {

Eigen::Vector3f Lighting::SampleSunDirection(float u1, float u2) const {
  if (sun_half_angle <= 0.0f) return sun_dir;
  const float r = sun_half_angle * std::sqrt(u1);
  const float phi = 2.0f * static_cast<float>(M_PI) * u2;
  return (std::cos(r) * sun_dir +
          std::sin(r) * (std::cos(phi) * sun_u + std::sin(phi) * sun_v))
      .normalized();
}

Rgb Lighting::SkyRadiance(const Eigen::Vector3f& dir) const {
  const float up = std::max(dir.z(), 0.0f);
  const float t = std::pow(up, 0.45f);
  Rgb c = sky_horizon + t * (sky_zenith - sky_horizon);
  // A faint glow around the sun so the sky is brighter on the sun's side.
  const float cs = std::max(dir.dot(sun_dir), 0.0f);
  c += (0.25f * cs * cs * cs * cs) * sky_horizon;
  return c;
}

Rgb Lighting::AmbientIrradiance(const Eigen::Vector3f& n) const {
  const float up = 0.5f * (1.0f + n.z());
  const float sun_on_ground = std::max(sun_dir.z(), 0.0f);
  const Rgb ground_irradiance =
      ground_albedo.cwiseProduct(sun_irradiance * sun_on_ground + sky_irradiance);
  return up * sky_irradiance + (1.0f - up) * ground_irradiance;
}

Lighting MakeLighting(const RenderParams& p) {
  Lighting l;
  const double az = p.sun_azimuth_deg * M_PI / 180.0;
  Eigen::Vector3f d(static_cast<float>(p.sun_radius * std::cos(az)),
                    static_cast<float>(p.sun_radius * std::sin(az)),
                    static_cast<float>(p.sun_height));
  l.sun_dir = d.normalized();
  const Eigen::Vector3f helper =
      std::abs(l.sun_dir.z()) < 0.9f ? Eigen::Vector3f::UnitZ() : Eigen::Vector3f::UnitX();
  l.sun_u = l.sun_dir.cross(helper).normalized();
  l.sun_v = l.sun_dir.cross(l.sun_u);
  l.sun_half_angle = static_cast<float>(0.5 * p.sun_shadow_soft_size * M_PI / 180.0);
  // Sunlight is slightly warm; the colour keeps unit luminance so strength means irradiance.
  l.sun_irradiance = static_cast<float>(p.sun_strength) * Rgb(1.04f, 1.0f, 0.92f);
  const float s = static_cast<float>(p.sky_strength);
  l.sky_zenith *= s;
  l.sky_horizon *= s;
  // Irradiance of a uniform-ish hemisphere: pi times the mean radiance (weighted to the zenith
  // colour, since cos-weighting favours the upper sky).
  l.sky_irradiance = static_cast<float>(M_PI) * (0.6f * l.sky_zenith + 0.4f * l.sky_horizon);
  return l;
}

}  // namespace clothwind::render
