#include "render/renderer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <cmath>

#include "render/fabric_patterns.h"
#include "render/flag_designs.h"
#include "render/noise.h"
#include "common/random.h"

namespace clothwind::render {

namespace {
constexpr float kInvPi = static_cast<float>(1.0 / M_PI);
constexpr float kShadowEps = 2e-3f;    // [m] shadow-ray offset along the geometric normal
// [m] how far rays look. Past what ValidateRenderParams lets a camera reach (1e4 m away, 1e3 m
// up): at 1e4 m a camera far away saw sky between the ground and the backdrop's foot. Nothing
// static stands beyond 500 m but the ground, so nearer cameras' pixels do not depend on it.
constexpr float kFar = 1e6f;
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

namespace {
// Slab test: can the ray org + t dir, t in (0, t_max), meet the box? Cheaper than asking
// Embree, and most rays of a frame pass far from the cloth.
inline bool RayMeetsBox(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float t_max,
                        const Eigen::AlignedBox3f& box) {
  if (box.isEmpty()) return false;
  float t0 = 0.0f, t1 = t_max;
  for (int k = 0; k < 3; ++k) {
    const float inv = 1.0f / dir[k];
    float a = (box.min()[k] - org[k]) * inv, b = (box.max()[k] - org[k]) * inv;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) return false;
  }
  return true;
}
}  // namespace

Renderer::StaticSample Renderer::ComputeStatic(const Eigen::Vector3f& org,
                                               const Eigen::Vector3f& dir,
                                               const Eigen::Vector3f& sun) const {
  StaticSample s;
  s.dir = dir;
  s.sun = sun;
  Hit hit;
  const bool any = scene_->IntersectStatic(org, dir, kFar, &hit);
  float tb, alpha;
  Rgb bg;
  if (backdrop_.Intersect(org, dir, &tb, &bg, &alpha) && (!any || tb < hit.t)) {
    // What shows through the backdrop's transparent texels: the sky, or, for a ray going down
    // past its top (a camera higher than its hills, 100 m up), the ground beyond it. It was sky
    // always, and such a camera saw a band of sky below the horizon.
    StaticSample behind;
    if (any && alpha < 1.0f) {
      behind = ShadeStatic(hit, sun);
    } else {
      behind.base = lighting_.SkyRadiance(dir);
      behind.what = kSky;
    }
    StaticSample seen = OverBackdrop(bg, alpha, tb, behind);
    seen.dir = dir;
    seen.sun = sun;
    return seen;
  }
  if (!any) {
    s.t = kFar;
    s.what = kSky;
    s.base = lighting_.SkyRadiance(dir);
    return s;
  }
  StaticSample shaded = ShadeStatic(hit, sun);
  shaded.dir = dir;
  shaded.sun = sun;
  return shaded;
}

Renderer::StaticSample Renderer::OverBackdrop(const Rgb& colour, float alpha, float t,
                                              const StaticSample& behind) {
  StaticSample s;
  s.dir = behind.dir;
  s.sun = behind.sun;
  s.t = t;
  s.what = alpha > 0.5f ? static_cast<uint8_t>(kBackdrop) : behind.what;
  s.base = alpha >= 1.0f ? colour : Rgb(colour + (1.0f - alpha) * behind.base);
  if (alpha < 1.0f && behind.can_see_sun) {
    s.can_see_sun = true;
    s.shadow_org = behind.shadow_org;
    s.sunlit = (1.0f - alpha) * behind.sunlit;
  }
  return s;
}

Renderer::StaticSample Renderer::ShadeStatic(const Hit& hit, const Eigen::Vector3f& sun) const {
  StaticSample s;
  s.t = hit.t;
  Rgb albedo;
  switch (hit.surface) {
    case Surface::kGround:
      albedo = GroundAlbedo(hit.point);
      s.what = kGroundSeen;
      break;
    case Surface::kFinial:
      albedo = kFinialAlbedo;
      s.what = kPoleSeen;
      break;
    default:
      albedo = kPoleAlbedo;
      s.what = kPoleSeen;
      break;
  }
  const Rgb brdf = kInvPi * albedo;
  s.base = brdf.cwiseProduct(lighting_.AmbientIrradiance(hit.normal));
  // n.l from the sun's centre (the disc is a few degrees wide; sampling it here would only add
  // grain), the sampled point of the disc for the shadow ray (soft shadow edges).
  const float ndl = hit.normal.dot(lighting_.sun_dir);
  if (ndl > 0.0f && hit.geom_normal.dot(sun) > 0.0f) {
    s.shadow_org = hit.point + kShadowEps * hit.geom_normal;
    s.can_see_sun = !options_.shadows || !scene_->OccludedStatic(s.shadow_org, sun, kFar);
    s.sunlit = brdf.cwiseProduct(ndl * lighting_.sun_irradiance);
  }
  return s;
}

Rgb Renderer::ShadeCloth(const Hit& hit, const Eigen::Vector3f& sun) const {
  const Rgb albedo = texture_.Sample(hit.uv.x(), hit.uv.y(), Wrap::kClamp);
  const Eigen::Vector3f& n = hit.normal;
  const float ndl = n.dot(lighting_.sun_dir);  // see ComputeStatic
  // Light through the cloth: thin fabric glows on its shaded side.
  const float tr = options_.translucency;
  Rgb irradiance = lighting_.AmbientIrradiance(n) + tr * lighting_.AmbientIrradiance(-n);
  const float weight = ndl >= 0.0f ? ndl : -tr * ndl;
  if (weight > 0.0f) {
    // The shadow ray leaves from the side of the flat triangle that faces the sun (the sampled
    // point of its disc), whatever the smoothed normal says. Where the two disagree (a coarse
    // mesh curving away from a grazing sun) the ray left from the normal's side, met its own
    // triangle, and single triangles went dark, flickering from frame to frame as the mesh moved
    // (smooth shading's "shadow terminator", which Cycles offsets for too).
    const float sun_side = hit.geom_normal.dot(sun) >= 0.0f ? 1.0f : -1.0f;
    const Eigen::Vector3f org = hit.point + (sun_side * kShadowEps) * hit.geom_normal;
    if (!options_.shadows || !scene_->Occluded(org, sun, kFar))
      irradiance += weight * lighting_.sun_irradiance;
  }
  return (kInvPi * albedo).cwiseProduct(irradiance);
}

Rgb Renderer::Resolve(const Eigen::Vector3f& org, const StaticSample& s, uint8_t* what) const {
  const Eigen::AlignedBox3f& box = scene_->cloth_bounds();
  Hit hit;
  if (RayMeetsBox(org, s.dir, s.t, box) && scene_->IntersectCloth(org, s.dir, s.t, &hit)) {
    *what = kClothSeen;
    return ShadeCloth(hit, s.sun);
  }
  *what = s.what;
  if (s.can_see_sun &&
      !(options_.shadows && RayMeetsBox(s.shadow_org, s.sun, kFar, box) &&
        scene_->OccludedCloth(s.shadow_org, s.sun, kFar)))
    return s.base + s.sunlit;
  return s.base;
}

Rgb Renderer::Trace(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float sun_u1,
                    float sun_u2) const {
  uint8_t what;
  return Resolve(org, ComputeStatic(org, dir, lighting_.SampleSunDirection(sun_u1, sun_u2)),
                 &what);
}

namespace {
// R2 low-discrepancy sequence (Roberts), shifted per pixel (Cranley-Patterson rotation):
// evenly spread sub-pixel and sun-disc samples for any count. Sample 0 is the pixel centre.
constexpr float kA1 = 0.7548776662f, kA2 = 0.5698402910f;

}  // namespace

PixelSample PixelSampleAt(uint64_t seed, int x, int y, int s) {
  Rng rng(HashSeed(seed, static_cast<uint64_t>(x), static_cast<uint64_t>(y)));
  const float ox = rng.UniformF(), oy = rng.UniformF();
  const float sx = rng.UniformF(), sy = rng.UniformF();
  PixelSample p;
  p.jx = s == 0 ? 0.5f : Fract(ox + s * kA1);
  p.jy = s == 0 ? 0.5f : Fract(oy + s * kA2);
  p.su = Fract(sx + s * kA1);
  p.sv = Fract(sy + s * kA2);
  return p;
}

namespace {

template <typename Fn>
void ForRows(int threads, int h, const Fn& fn) {
  auto body = [&](const tbb::blocked_range<int>& r) {
    for (int y = r.begin(); y < r.end(); ++y) fn(y);
  };
  if (threads == 1) {
    body(tbb::blocked_range<int>(0, h));
  } else {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] { tbb::parallel_for(tbb::blocked_range<int>(0, h, 4), body); });
  }
}

inline float Luma(const Rgb& c) { return Tone(0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]); }
}  // namespace

void Renderer::BuildCache() {
  const int w = camera_.width, h = camera_.height, spp = params_.samples;
  cache_.resize(static_cast<size_t>(w) * h * spp);
  const Eigen::Vector3f org = camera_.position.cast<float>();
  ForRows(options_.threads, h, [&](int y) {
    for (int x = 0; x < w; ++x)
      for (int s = 0; s < spp; ++s) {
        const PixelSample ps = PixelSampleAt(params_.seed, x, y, s);
        const Eigen::Vector3f dir = camera_.RayDirection(x + ps.jx, y + ps.jy).cast<float>();
        cache_[(static_cast<size_t>(y) * w + x) * spp + s] =
            ComputeStatic(org, dir, lighting_.SampleSunDirection(ps.su, ps.sv));
      }
  });
}

cv::Mat Renderer::RenderLinear(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                               const Eigen::MatrixXd& UV) {
  scene_->SetCloth(V, F, UV);
  if (cache_.empty()) BuildCache();
  const int w = camera_.width, h = camera_.height, spp = params_.samples;
  const Eigen::Vector3f org = camera_.position.cast<float>();
  cv::Mat out(h, w, CV_32FC3);
  std::vector<uint8_t> what(static_cast<size_t>(w) * h);
  std::vector<float> luma(static_cast<size_t>(w) * h);
  // Pass 1: one sample (the pixel centre) everywhere.
  ForRows(options_.threads, h, [&](int y) {
    cv::Vec3f* row = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const Rgb c = Resolve(org, cache_[i * spp], &what[i]);
      luma[i] = Luma(c);
      row[x] = cv::Vec3f(c[0], c[1], c[2]);
    }
  });
  if (spp == 1) return out;
  // Pass 2: the remaining samples only where a neighbour sees another surface or differs in
  // brightness (silhouettes, texture and shadow edges); elsewhere one sample is the answer.
  constexpr float kContrast = 0.04f;
  ForRows(options_.threads, h, [&](int y) {
    cv::Vec3f* row = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      bool edge = false;
      const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
      for (int k = 0; k < 4 && !edge; ++k) {
        if (nx[k] < 0 || nx[k] >= w || ny[k] < 0 || ny[k] >= h) continue;
        const size_t j = static_cast<size_t>(ny[k]) * w + nx[k];
        edge = what[j] != what[i] || std::abs(luma[j] - luma[i]) > kContrast;
      }
      if (!edge) continue;
      // The jittered samples only: with the centre among them (weight 1/spp) an edge pixel's
      // coverage was pulled towards the centre's side (0.30 for a true 0.43 at 4 samples).
      Rgb sum = Rgb::Zero();
      uint8_t wt;
      for (int s = 1; s < spp; ++s) sum += Resolve(org, cache_[i * spp + s], &wt);
      sum /= static_cast<float>(spp - 1);
      row[x] = cv::Vec3f(sum[0], sum[1], sum[2]);
    }
  });
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
