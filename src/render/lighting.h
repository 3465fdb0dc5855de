#ifndef CLOTHWIND_RENDER_LIGHTING_H_
#define CLOTHWIND_RENDER_LIGHTING_H_

#include <Eigen/Core>

#include "render/color.h"
#include "render/render_params.h"

namespace clothwind::render {

// Outdoor light: a sun (distant disc light giving soft shadows) and a sky (gradient seen in the
// background, hemisphere ambient light on surfaces, plus light bounced from the ground).
// Indirect light between the cloth, pole and ground is not traced: the ambient term stands in
// for Cycles' bounces (Table 2 cycles_bounces), which on an open scene add little.
struct Lighting {
  Eigen::Vector3f sun_dir = Eigen::Vector3f(0, 0, 1);  // unit, towards the sun
  Eigen::Vector3f sun_u = Eigen::Vector3f(1, 0, 0);    // orthonormal basis across sun_dir
  Eigen::Vector3f sun_v = Eigen::Vector3f(0, 1, 0);
  float sun_half_angle = 0.0f;                 // [rad] angular radius of the sun disc
  Rgb sun_irradiance = Rgb::Constant(5.0f);     // at normal incidence, linear RGB
  Rgb sky_zenith = Rgb(0.22f, 0.36f, 0.70f);    // radiance straight up
  Rgb sky_horizon = Rgb(0.62f, 0.70f, 0.80f);   // radiance at the horizon
  Rgb sky_irradiance = Rgb::Zero();             // from the sky on an upward-facing surface
  Rgb ground_albedo = Rgb(0.12f, 0.20f, 0.07f); // mean albedo of grass, for the bounce term

  // Direction towards a point of the sun disc, uniform over the disc.
  // Inputs: u1, u2  uniform numbers in [0,1).
  Eigen::Vector3f SampleSunDirection(float u1, float u2) const;

  // Radiance of the sky in a (unit) direction (below the horizon: the horizon colour).
  Rgb SkyRadiance(const Eigen::Vector3f& dir) const;

  // Irradiance from sky and ground bounce on a surface with unit normal n (no occlusion).
  Rgb AmbientIrradiance(const Eigen::Vector3f& n) const;
};

// Lighting of a clip from ζ: sun direction from (sun_radius, sun_azimuth_deg, sun_height)
// relative to the ground point below the mesh's centre, disc angular diameter
// sun_shadow_soft_size, irradiance sun_strength (slightly warm), sky scaled by sky_strength.
Lighting MakeLighting(const RenderParams& p);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_LIGHTING_H_
