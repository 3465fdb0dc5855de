#ifndef CLOTHWIND_RENDER_RENDERER_H_
#define CLOTHWIND_RENDER_RENDERER_H_

#include <Eigen/Core>
#include <memory>
#include <vector>
#include <opencv2/core.hpp>

#include "render/background.h"
#include "render/camera.h"
#include "render/embree_scene.h"
#include "render/lighting.h"
#include "render/render_params.h"
#include "render/texture.h"

namespace clothwind::render {

struct RenderOptions {
  int threads = 0;       // worker threads for the pixels; 0 = all the machine has
  bool shadows = true;   // trace shadow rays (off: every surface sees the whole sun)
  float translucency = 0.2f;  // fraction of light on one side of the cloth seen on the other
};

// Renders clips of one parameter set ζ: a direct-lighting ray tracer on Embree (camera rays,
// one shadow ray to a point of the sun disc per sample, analytic sky/ground ambient), which
// for these open outdoor scenes looks like Cycles' image at a small fraction of its cost.
//
// Build one Renderer per clip (textures, backdrop and static geometry are made once), then
// call RenderLinear/RenderFrame for each frame's mesh. Not thread-safe itself; it uses
// RenderOptions::threads workers inside each call. Images depend only on ζ and the mesh
// (pixel samples come from HashSeed(ζ.seed, x, y)), not on the thread count.
class Renderer {
 public:
  // Throws std::invalid_argument on invalid ζ and std::runtime_error if a background image
  // cannot be read.
  explicit Renderer(const RenderParams& p, const RenderOptions& options = RenderOptions());

  // Renders scene radiance (linear RGB, CV_32FC3 in R,G,B order, height by width).
  // Inputs:
  //   V   #V by 3 cloth vertex positions [m] in the simulator's frame (z up, hoist on the
  //       z axis from z = 0, wind along +x); lifted by ζ.mesh_height here
  //   F   #F by 3 faces (vertex indices)
  //   UV  #V by 2 texture coordinates in [0,1] (u hoist to fly, v bottom to top)
  cv::Mat RenderLinear(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                       const Eigen::MatrixXd& UV);

  // RenderLinear followed by Develop: an 8-bit frame (CV_8UC3, OpenCV's B,G,R order).
  cv::Mat RenderFrame(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                      const Eigen::MatrixXd& UV);

  // Radiance along one ray through the current scene (after RenderLinear/SetCloth), without
  // the cache (same result as a camera sample along that ray).
  // Inputs: org [m]; dir unit; sun_u1, sun_u2 in [0,1): which point of the sun disc the shadow
  //   ray aims at.
  Rgb Trace(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float sun_u1,
            float sun_u2) const;

  const RenderParams& params() const { return params_; }
  const PinholeCamera& camera() const { return camera_; }
  const Lighting& lighting() const { return lighting_; }
  const Texture& cloth_texture() const { return texture_; }
  const Backdrop& backdrop() const { return backdrop_; }
  EmbreeScene& scene() { return *scene_; }
  // Changing options drops the cache of static radiance.
  void set_options(const RenderOptions& o) {
    options_ = o;
    cache_.clear();
  }
  const RenderOptions& options() const { return options_; }

  // What a camera sample saw, for the edge test (antialiasing where it changes).
  enum What : uint8_t { kSky = 0, kBackdrop = 1, kGroundSeen = 2, kPoleSeen = 3, kClothSeen = 4 };

  // What one camera sample sees of the static scene (pole, ground, backdrop, sky), which does
  // not change during a clip: computed on the first frame, reused on the others, so that a
  // frame costs little more than the rays that meet the cloth or its shadow.
  struct StaticSample {
    // Zero until set: a sky sample has no shadow ray, and copies of it were of uninitialised memory.
    Eigen::Vector3f dir = Eigen::Vector3f::Zero();         // camera ray direction (unit)
    Eigen::Vector3f shadow_org = Eigen::Vector3f::Zero();  // where a shadow ray to the sun leaves
    Eigen::Vector3f sun = Eigen::Vector3f::Zero();         // the sun-disc direction this sample uses
    Rgb base = Rgb::Zero();      // radiance without direct sun (sky, backdrop, ambient)
    Rgb sunlit = Rgb::Zero();    // radiance added when the sun sample is not blocked
    float t = 0.0f;              // distance to the static surface / backdrop [m]
    uint8_t what = 0;            // Surface (or sky/backdrop) seen, for the edge test
    bool can_see_sun = false;    // lit unless the cloth is in the way
  };

  // The sample of a ray meeting the backdrop in front of whatever lies behind it: the backdrop's
  // filtered colour over it, by its coverage. Why a function of its own: a ray going down past a
  // backdrop's top (a camera above its hills) sees the ground through its transparent texels, and
  // the sky always shown there drew a band of sky below the horizon.
  // Inputs:
  //   colour  the backdrop's filtered texel colour, already premultiplied by alpha (transparent
  //           texels hold 0; multiplying again drew a dark fringe where hills meet the sky)
  //   alpha   its coverage in [0, 1]
  //   t       distance to the backdrop [m]
  //   behind  what the ray meets beyond it (sky, or the ground's ShadeStatic sample)
  // Returns behind's sample with base = colour + (1 - alpha) behind.base, sunlit scaled by
  // (1 - alpha) (the sun and shadows reach only what shows through), t = t, and `what` the
  // backdrop where alpha > 0.5, else behind's; alpha 1 is the backdrop alone, with no sun.
  static StaticSample OverBackdrop(const Rgb& colour, float alpha, float t, const StaticSample& behind);

 private:
  StaticSample ComputeStatic(const Eigen::Vector3f& org, const Eigen::Vector3f& dir,
                             const Eigen::Vector3f& sun) const;
  // Radiance of one camera sample this frame; `what` gets the surface it saw.
  Rgb Resolve(const Eigen::Vector3f& org, const StaticSample& s, uint8_t* what) const;
  Rgb ShadeCloth(const Hit& hit, const Eigen::Vector3f& sun) const;
  // A static surface's sample (ground, pole) at `hit`, lit by the sun sample `sun`; dir and sun
  // left for the caller.
  StaticSample ShadeStatic(const Hit& hit, const Eigen::Vector3f& sun) const;
  Rgb GroundAlbedo(const Eigen::Vector3f& p) const;
  void BuildCache();

  RenderParams params_;
  RenderOptions options_;
  PinholeCamera camera_;
  Lighting lighting_;
  Texture texture_;
  Texture grass_;
  Backdrop backdrop_;
  std::unique_ptr<EmbreeScene> scene_;
  std::vector<StaticSample> cache_;  // width * height * samples, pixel-major
};

// Where sample s of pixel (x, y) looks and which point of the sun disc its shadow ray aims at:
// an R2 low-discrepancy sequence shifted per pixel by Rng(HashSeed(seed, x, y)), so images do
// not depend on the thread count. Sample 0 is the pixel centre.
// Inputs: seed  ζ.seed; x, y  pixel; s  sample index in [0, ζ.samples).
// Outputs (returned): jx, jy  offset in the pixel, in [0,1) (the ray goes through (x + jx,
//   y + jy)); su, sv  in [0,1), the sun-disc point (Lighting::SampleSunDirection).
struct PixelSample {
  float jx, jy, su, sv;
};
PixelSample PixelSampleAt(uint64_t seed, int x, int y, int s);

// Film response and sRGB encoding of a radiance image (CV_32FC3 RGB) into an 8-bit frame
// (CV_8UC3 BGR), per channel: ToSrgb8(Tone(L)).
cv::Mat Develop(const cv::Mat& linear_rgb);

// The cloth texture ζ names (flag design or fabric pattern with ζ.texture_seed's colours).
Texture MakeClothTexture(const RenderParams& p);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_RENDERER_H_
