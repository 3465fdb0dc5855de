#include "render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "render/fabric_patterns.h"
#include "render/flag_designs.h"
#include "render/noise.h"
#include "render/random.h"

namespace clothwind::render {

namespace {
constexpr float kInvPi = static_cast<float>(1.0 / M_PI);
constexpr float kShadowEps = 2e-3f;    // [m] shadow-ray offset along the geometric normal
constexpr float kFar = 1e4f;           // [m]
constexpr float kGrassTile = 6.0f;     // [m] period of the grass texture
const Rgb kPoleAlbedo(0.62f, 0.62f, 0.60f);
const Rgb kFinialAlbedo(0.55f, 0.42f, 0.12f);

inline float Fract(float x) { return x - std::floor(x); }
}  // namespace

Texture MakeClothTexture(const RenderParams& p) {
  if (p.texture_kind == "flag") {
    const int w = 300;
    const int h = std::max(2, static_cast<int>(std::lround(w / p.mesh_aspect_ratio)));
    return DrawFlag(FlagDesignFromName(p.texture_name), SampleFlagColours(p.texture_seed), w, h);
  }
  return DrawFabric(FabricPatternFromName(p.texture_name), p.texture_seed, 256);
}

Renderer::Renderer(const RenderParams& p, const RenderOptions& options)
    : params_(p), options_(options) {
  ValidateRenderParams(p);
  camera_ = PlaceCamera(p);
  lighting_ = MakeLighting(p);
  texture_ = MakeClothTexture(p);
  backdrop_ = MakeBackdrop(p, camera_);
  // Grass: tileable noise (periodic lattice by wrapping the lookup), two scales of clumps.
  const int n = 256;
  grass_ = Texture(n, n);
  const uint64_t gs = HashSeed(p.background_seed, 0x9a55);
  const Rgb base = FromSrgb8(92, 128, 52), dry = FromSrgb8(140, 140, 70);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      // Sum of noise over a torus so the tile repeats without seams.
      const float fx = static_cast<float>(x) / n, fy = static_cast<float>(y) / n;
      auto tile = [&](float scale, uint64_t s) {
        const float a = ValueNoise(fx * scale, fy * scale, s);
        const float b = ValueNoise((fx - 1) * scale, fy * scale, s);
        const float c = ValueNoise(fx * scale, (fy - 1) * scale, s);
        const float d = ValueNoise((fx - 1) * scale, (fy - 1) * scale, s);
        return (1 - fx) * (1 - fy) * a + fx * (1 - fy) * b + (1 - fx) * fy * c + fx * fy * d;
      };
      const float clumps = tile(6.0f, gs), blades = tile(64.0f, gs + 1);
      const float patch = tile(2.0f, gs + 2);
      Rgb c = base + std::clamp(patch * 1.3f - 0.5f, 0.0f, 1.0f) * 0.5f * (dry - base);
      grass_.at(x, y) = c * (0.65f + 0.45f * clumps) * (0.8f + 0.4f * blades);
    }
  scene_ = std::make_unique<EmbreeScene>(p);
}

Rgb Renderer::GroundAlbedo(const Eigen::Vector3f& p) const {
  return grass_.Sample(p.x() / kGrassTile, p.y() / kGrassTile, Wrap::kRepeat);
}

Rgb Renderer::Shade(const Hit& hit, const Eigen::Vector3f& dir, float sun_u1,
                    float sun_u2) const {
  Rgb albedo;
  switch (hit.surface) {
    case Surface::kCloth:
      albedo = texture_.Sample(hit.uv.x(), hit.uv.y(), Wrap::kClamp);
      break;
    case Surface::kGround:
      albedo = GroundAlbedo(hit.point);
      break;
    case Surface::kFinial:
      albedo = kFinialAlbedo;
      break;
    default:
      albedo = kPoleAlbedo;
      break;
  }
  const Eigen::Vector3f& n = hit.normal;
  const Eigen::Vector3f sun = lighting_.SampleSunDirection(sun_u1, sun_u2);
  const float ndl = n.dot(sun);
  Rgb irradiance = lighting_.AmbientIrradiance(n);
  if (hit.surface == Surface::kCloth) {
    // Light through the cloth: thin fabric glows on its shaded side.
    const float t = options_.translucency;
    irradiance += t * lighting_.AmbientIrradiance(-n);
    const float side = ndl >= 0.0f ? 1.0f : -1.0f;
    const float weight = ndl >= 0.0f ? ndl : -t * ndl;
    if (weight > 0.0f) {
      const Eigen::Vector3f org = hit.point + (side * kShadowEps) * hit.geom_normal;
      if (!options_.shadows || !scene_->Occluded(org, sun, kFar))
        irradiance += weight * lighting_.sun_irradiance;
    }
  } else if (ndl > 0.0f && hit.geom_normal.dot(sun) > 0.0f) {
    const Eigen::Vector3f org = hit.point + kShadowEps * hit.geom_normal;
    if (!options_.shadows || !scene_->Occluded(org, sun, kFar))
      irradiance += ndl * lighting_.sun_irradiance;
  }
  return (kInvPi * albedo).cwiseProduct(irradiance);
}

Rgb Renderer::Trace(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float sun_u1,
                    float sun_u2) const {
  Hit hit;
  const bool any = scene_->Intersect(org, dir, kFar, &hit);
  float tb, alpha;
  Rgb bg;
  if (backdrop_.Intersect(org, dir, &tb, &bg, &alpha) && (!any || tb < hit.t)) {
    if (alpha >= 1.0f) return bg;
    return alpha * bg + (1.0f - alpha) * lighting_.SkyRadiance(dir);
  }
  if (!any) return lighting_.SkyRadiance(dir);
  return Shade(hit, dir, sun_u1, sun_u2);
}

cv::Mat Renderer::RenderLinear(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                               const Eigen::MatrixXd& UV) {
  scene_->SetCloth(V, F, UV);
  const int w = camera_.width, h = camera_.height, spp = params_.samples;
  cv::Mat out(h, w, CV_32FC3);
  const Eigen::Vector3f org = camera_.position.cast<float>();
  const Eigen::Vector3f fwd = camera_.forward.cast<float>();
  const Eigen::Vector3f right = camera_.right.cast<float>() / static_cast<float>(camera_.focal_px);
  const Eigen::Vector3f down = camera_.down.cast<float>() / static_cast<float>(camera_.focal_px);
  const float cx = static_cast<float>(camera_.cx), cy = static_cast<float>(camera_.cy);
  // R2 low-discrepancy sequence (Roberts), shifted per pixel (Cranley-Patterson rotation):
  // evenly spread sub-pixel and sun-disc samples for any count.
  constexpr float kA1 = 0.7548776662f, kA2 = 0.5698402910f;
  auto rows = [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y) {
      cv::Vec3f* row = out.ptr<cv::Vec3f>(y);
      for (int x = 0; x < w; ++x) {
        Rng rng(HashSeed(params_.seed, static_cast<uint64_t>(x), static_cast<uint64_t>(y)));
        const float ox = rng.UniformF(), oy = rng.UniformF();
        const float sx = rng.UniformF(), sy = rng.UniformF();
        Rgb sum = Rgb::Zero();
        for (int s = 0; s < spp; ++s) {
          float jx = 0.5f, jy = 0.5f;
          if (spp > 1) {
            jx = Fract(ox + s * kA1);
            jy = Fract(oy + s * kA2);
          }
          const Eigen::Vector3f dir =
              (fwd + (x + jx - cx) * right + (y + jy - cy) * down).normalized();
          sum += Trace(org, dir, Fract(sx + s * kA1), Fract(sy + s * kA2));
        }
        sum /= static_cast<float>(spp);
        row[x] = cv::Vec3f(sum[0], sum[1], sum[2]);
      }
    }
  };
  if (options_.threads == 1) {
    rows(tbb::blocked_range<int>(0, h));
  } else {
    tbb::task_arena arena(options_.threads > 0 ? options_.threads
                                               : tbb::task_arena::automatic);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<int>(0, h, 4), rows); });
  }
  return out;
}

cv::Mat Renderer::RenderFrame(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                              const Eigen::MatrixXd& UV) {
  return Develop(RenderLinear(V, F, UV));
}

cv::Mat Develop(const cv::Mat& linear_rgb) {
  CV_Assert(linear_rgb.type() == CV_32FC3);
  cv::Mat out(linear_rgb.rows, linear_rgb.cols, CV_8UC3);
  for (int y = 0; y < linear_rgb.rows; ++y) {
    const cv::Vec3f* in = linear_rgb.ptr<cv::Vec3f>(y);
    cv::Vec3b* o = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < linear_rgb.cols; ++x)
      o[x] = cv::Vec3b(ToSrgb8(Tone(in[x][2])), ToSrgb8(Tone(in[x][1])), ToSrgb8(Tone(in[x][0])));
  }
  return out;
}

}  // namespace clothwind::render
