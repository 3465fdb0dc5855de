#ifndef CLOTHWIND_RENDER_BACKGROUND_H_
#define CLOTHWIND_RENDER_BACKGROUND_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/render_params.h"
#include "render/texture.h"

namespace clothwind::render {

// The backdrop: a picture on a vertical wall behind the mesh, facing the camera, standing on
// the ground (seed Table 2: background_image, background_offset, background_scale).
//
// Placement: the wall is kBackdropDistance metres beyond the mesh's centre along the camera's
// horizontal viewing direction; at background_scale = 1 it is kBackdropHeight metres tall and
// as wide as the picture's aspect says; background_offset shifts the picture sideways [m]. It
// repeats mirrored sideways so no offset uncovers a gap. Above its top (and where the picture
// is transparent, as procedural skies are) what lies beyond shows: the renderer's sky, or the
// ground for a ray going down (a camera above the picture's field or hills). Texels hold radiance, so
// the wall is not lit again: a photograph carries its own light.
struct Backdrop {
  static constexpr float kBackdropDistance = 22.0f;  // [m]
  static constexpr float kBackdropHeight = 45.0f;    // [m] at scale 1

  Texture image;                     // radiance + alpha
  Eigen::Vector3f origin;            // [m] bottom centre of the picture on the ground
  Eigen::Vector3f normal;            // unit, towards the camera (horizontal)
  Eigen::Vector3f across;            // unit, horizontal along the wall (image +u)
  float width = 1.0f, height = 1.0f; // [m] of one copy of the picture

  // Intersects a ray with the wall.
  // Inputs: org [m], dir (unit) of the ray.
  // Outputs: t  distance [m]; radiance, alpha  the picture there.
  // Returns false if the ray does not reach the wall (parallel or pointing away) or passes
  // below the ground.
  bool Intersect(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float* t, Rgb* radiance,
                 float* alpha) const;
};

// Builds the backdrop of ζ as seen from `camera`: loads p.background_image (any format
// cv::imread reads; throws std::runtime_error naming the file if it cannot) or, when that is
// empty, draws ProceduralBackdrop(p.background_seed).
Backdrop MakeBackdrop(const RenderParams& p, const PinholeCamera& camera);

// A plausible outdoor backdrop without photographs: a field, hedges or a tree line, sometimes
// buildings, hills; transparent above (the sky is the renderer's). Texels hold radiance.
// Inputs: seed; width, height  texels (the picture is 2:1, 90 m by 45 m at scale 1).
Texture ProceduralBackdrop(uint64_t seed, int width = 1024, int height = 512);

// The images (.jpg .jpeg .png .bmp, any case) directly in `folder`, sorted by name, each read
// once whole (at 1/8 size) to check it.
// Throws std::runtime_error naming the folder if it does not exist or holds no image, and the
// file if one cannot be read as an image.
std::vector<std::string> ListBackgroundImages(const std::string& folder);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_BACKGROUND_H_
