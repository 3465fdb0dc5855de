#include "render/render_params.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>

#include "render/camera.h"

#include "render/fabric_patterns.h"
#include "render/flag_designs.h"
#include "common/random.h"

namespace clothwind::render {

std::string SceneKindName(SceneKind kind) { return kind == SceneKind::kFlag ? "flag" : "cloth"; }

SceneKind SceneKindFromName(const std::string& name) {
  if (name == "flag") return SceneKind::kFlag;
  if (name == "cloth") return SceneKind::kCloth;
  throw std::invalid_argument("render params: field 'scene' is '" + name +
                              "', expected 'flag' or 'cloth'");
}

bool CameraRanges::operator==(const CameraRanges& o) const {
  return height_min == o.height_min && height_max == o.height_max && radius_min == o.radius_min &&
         radius_max == o.radius_max && angle_max_deg == o.angle_max_deg;
}

CameraRanges TableTwoCameraRanges(SceneKind kind) {
  CameraRanges r;
  if (kind == SceneKind::kCloth) {
    r.height_min = 0.5, r.height_max = 2.0;
    r.radius_min = 1.0, r.radius_max = 2.5;
    r.angle_max_deg = 5.0;
  }
  return r;
}

void ValidateCameraRanges(const CameraRanges& r) {
  const auto check = [](bool ok, const std::string& field, double lo, double hi, const std::string& expected) {
    if (!ok) {
      std::ostringstream m;
      m << "camera ranges: " << field << " is [" << lo << ", " << hi << "], expected " << expected;
      throw std::invalid_argument(m.str());
    }
  };
  // Finite: an infinite maximum passed "max >= min", failed every simulation with a misleading
  // camera error and went into a dataset's header as null.
  // Bounded too: a radius of 1e308 m failed every simulation as "viewing direction is vertical".
  check(r.height_min > 0 && r.height_max >= r.height_min && r.height_max <= 100, "camera height", r.height_min,
        r.height_max, "0 < min <= max <= 100 [m]");
  check(r.radius_min >= kMinCameraRadius && r.radius_max >= r.radius_min && r.radius_max <= 1000, "camera radius",
        r.radius_min, r.radius_max, "0.1 <= min <= max <= 1000 [m]");
  check(r.angle_max_deg >= 0 && r.angle_max_deg < 90, "camera angle", -r.angle_max_deg, r.angle_max_deg,
        "a half-range in [0, 90) deg");
}

RenderParams SampleRenderParams(SceneKind kind, uint64_t seed,
                                const std::vector<std::string>& background_images) {
  return SampleRenderParams(kind, seed, background_images, TableTwoCameraRanges(kind));
}

RenderParams SampleRenderParams(SceneKind kind, uint64_t seed,
                                const std::vector<std::string>& background_images,
                                const CameraRanges& camera) {
  ValidateCameraRanges(camera);
  Rng rng(HashSeed(seed, 0x2e7a));
  RenderParams p;
  p.scene = kind;
  p.seed = seed;
  if (!background_images.empty())
    p.background_image = background_images[rng.UniformInt(static_cast<int>(background_images.size()))];
  p.background_seed = rng.Next();
  p.background_offset = rng.Uniform(-20, 20);
  p.background_scale = rng.Uniform(0.6, 1.0);
  p.sun_height = rng.Uniform(4, 10);
  p.sun_radius = rng.Uniform(0, 5);
  p.sun_azimuth_deg = rng.Uniform(-180, 180);
  p.sun_strength = rng.Uniform(2, 10);
  p.sun_shadow_soft_size = rng.Uniform(2, 10);
  p.sky_strength = rng.Uniform(0.7, 1.3);
  p.texture_seed = rng.Next();
  if (kind == SceneKind::kFlag) {
    p.camera_height = rng.Uniform(camera.height_min, camera.height_max);
    p.camera_radius = rng.Uniform(camera.radius_min, camera.radius_max);
    p.camera_angle_deg = rng.Uniform(-camera.angle_max_deg, camera.angle_max_deg);
    p.camera_fov_deg = 45.0;
    p.mesh_height = 4.6;
    p.mesh_width = 3.0;
    p.mesh_aspect_ratio = 1.5;
    p.texture_kind = "flag";
    p.texture_name = FlagDesignName(static_cast<FlagDesign>(rng.UniformInt(kNumFlagDesigns)));
  } else {
    p.camera_height = rng.Uniform(camera.height_min, camera.height_max);
    p.camera_radius = rng.Uniform(camera.radius_min, camera.radius_max);
    p.camera_angle_deg = rng.Uniform(-camera.angle_max_deg, camera.angle_max_deg);
    p.camera_fov_deg = 45.0;
    p.mesh_height = 2.0;
    p.mesh_width = 1.0;
    p.mesh_aspect_ratio = 1.0;
    p.texture_kind = "fabric";
    p.texture_name =
        FabricPatternName(static_cast<FabricPattern>(rng.UniformInt(kNumFabricPatterns)));
  }
  return p;
}

nlohmann::json ToJson(const RenderParams& p) {
  nlohmann::json j{
      {"scene", SceneKindName(p.scene)},
      {"seed", p.seed},
      {"background_image", p.background_image},
      {"background_seed", p.background_seed},
      {"background_offset", p.background_offset},
      {"background_scale", p.background_scale},
      {"sun_height", p.sun_height},
      {"sun_radius", p.sun_radius},
      {"sun_azimuth_deg", p.sun_azimuth_deg},
      {"sun_strength", p.sun_strength},
      {"sun_shadow_soft_size", p.sun_shadow_soft_size},
      {"sky_strength", p.sky_strength},
      {"samples", p.samples},
      {"camera_height", p.camera_height},
      {"camera_radius", p.camera_radius},
      {"camera_angle_deg", p.camera_angle_deg},
      {"camera_fov_deg", p.camera_fov_deg},
      {"mesh_height", p.mesh_height},
      {"mesh_width", p.mesh_width},
      {"mesh_aspect_ratio", p.mesh_aspect_ratio},
      {"texture_kind", p.texture_kind},
      {"texture_name", p.texture_name},
      {"texture_seed", p.texture_seed},
      {"width", p.width},
      {"height", p.height},
      {"fps", p.fps},
  };
  if (p.has_look_at) j["look_at"] = {p.look_at[0], p.look_at[1], p.look_at[2]};
  return j;
}

namespace {
// Refuses a vertex that is not finite: its box made a look-at point of NaN, refused as "viewing
// direction is vertical", which named neither the frame nor the vertex.
void CheckFiniteFrame(const Eigen::MatrixXd& V, size_t frame) {
  if (V.allFinite()) return;
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    for (int k = 0; k < 3; ++k)
      if (!std::isfinite(V(i, k))) {
        std::ostringstream m;
        m << "FrameClip: frame " << frame << ", vertex " << i << " has coordinate " << "xyz"[k]
          << " = " << V(i, k) << ", expected a finite value";
        throw std::invalid_argument(m.str());
      }
}
}  // namespace

void FrameClip(const std::vector<Eigen::MatrixXd>& frames, RenderParams* p) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (size_t f = 0; f < frames.size(); ++f) {
    const Eigen::MatrixXd& V = frames[f];
    if (V.cols() != 3 || V.rows() == 0)
      throw std::invalid_argument("FrameClip: every frame must be #V by 3 with #V > 0");
    CheckFiniteFrame(V, f);
    lo = lo.cwiseMin(V.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(V.colwise().maxCoeff().transpose());
  }
  if (frames.empty()) throw std::invalid_argument("FrameClip: no frames");
  const Eigen::Vector3d c = 0.5 * (lo + hi);
  p->has_look_at = true;
  p->look_at[0] = c.x();
  p->look_at[1] = c.y();
  p->look_at[2] = c.z() + p->mesh_height;
  // Widen (never narrow) the field of view so the box fits with a 5 % margin: a flag hanging
  // down the pole is taller than a flying one is long.
  const PinholeCamera cam = PlaceCamera(*p);
  double need = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d q((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                            ((corner & 4) ? hi.z() : lo.z()) + p->mesh_height);
    const Eigen::Vector3d d = q - cam.position;
    const double z = std::max(d.dot(cam.forward), 1e-3);
    // camera_fov_deg is horizontal: a frame H px tall spans H / W of its tangent vertically (a
    // hanging flag overflowed a 400x200 frame top and bottom).
    need = std::max({need, std::abs(d.dot(cam.right)) / z,
                     std::abs(d.dot(cam.down)) / z * p->width / static_cast<double>(p->height)});
  }
  const double fov = 2.0 * std::atan(need / 0.95) * 180.0 / M_PI;
  // The widening stops at 120 deg; a field of view already wider stays (the cap applied to it
  // too narrowed a valid 150 deg to 120).
  p->camera_fov_deg = std::max(p->camera_fov_deg, std::min(fov, kFrameClipMaxFovDeg));
}

Eigen::Vector2d MeasureClothSize(const Eigen::MatrixXd& V, const Eigen::MatrixXi& F,
                                 const Eigen::MatrixXd& UV) {
  if (V.cols() != 3 || UV.cols() != 2 || UV.rows() != V.rows() || F.cols() != 3)
    throw std::invalid_argument("MeasureClothSize: expected V #V by 3, F #F by 3, UV #V by 2");
  // A diverged frame is named as such (it read as "texture coordinates span no area").
  for (Eigen::Index i = 0; i < V.rows(); ++i)
    if (!V.row(i).allFinite() || !UV.row(i).allFinite())
      throw std::invalid_argument("MeasureClothSize: vertex " + std::to_string(i) +
                                  " has a coordinate that is not finite (a diverged frame?)");
  double width = 0.0, height = 0.0, weight = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const int a = F(f, 0), b = F(f, 1), c = F(f, 2);
    if (std::min({a, b, c}) < 0 || std::max({a, b, c}) >= V.rows())
      throw std::invalid_argument("MeasureClothSize: F(" + std::to_string(f) +
                                  ", :) is not a face of the " + std::to_string(V.rows()) +
                                  " vertices");
    // The affine map of the face from texture to world: [e1 e2] = J [t1 t2], J = [dX/du dX/dv].
    Eigen::Matrix2d T;
    T.col(0) = (UV.row(b) - UV.row(a)).transpose();
    T.col(1) = (UV.row(c) - UV.row(a)).transpose();
    const double area = 0.5 * std::abs(T.determinant());  // in texture space
    if (!(area > 0.0)) continue;  // degenerate in texture space: says nothing about the size
    Eigen::Matrix<double, 3, 2> E;
    E.col(0) = (V.row(b) - V.row(a)).transpose();
    E.col(1) = (V.row(c) - V.row(a)).transpose();
    const Eigen::Matrix<double, 3, 2> J = E * T.inverse();
    width += area * J.col(0).norm();
    height += area * J.col(1).norm();
    weight += area;
  }
  if (!(weight > 0.0) || !std::isfinite(width) || !std::isfinite(height))
    throw std::invalid_argument(
        "MeasureClothSize: the texture coordinates span no area, so the cloth has no measurable size");
  return Eigen::Vector2d(width / weight, height / weight);
}

void SetMeshSize(const Eigen::Vector2d& size, RenderParams* p) {
  p->mesh_width = size.x();
  p->mesh_aspect_ratio = size.x() / size.y();
}

std::string MeshSizeMismatch(const RenderParams& p, const Eigen::Vector2d& size, double tolerance) {
  const double w = size.x(), h = size.y();
  std::ostringstream m;
  if (!(std::abs(w / p.mesh_width - 1.0) <= tolerance)) {
    m << "field 'mesh_width' is " << p.mesh_width << " m but the cloth being rendered is " << w
      << " m long (u, hoist to fly); expected within " << 100 * tolerance << " %";
  } else if (!(std::abs(h / p.MeshRestHeight() - 1.0) <= tolerance)) {
    m << "field 'mesh_aspect_ratio' is " << p.mesh_aspect_ratio << " (" << p.MeshRestHeight()
      << " m tall) but the cloth being rendered is " << w << " m by " << h << " m (aspect "
      << w / h << "); expected its height within " << 100 * tolerance << " %";
  }
  return m.str();
}

namespace {
const nlohmann::json& Field(const nlohmann::json& j, const char* name) {
  if (!j.is_object()) throw std::invalid_argument("render params: expected a JSON object");
  auto it = j.find(name);
  if (it == j.end())
    throw std::invalid_argument(std::string("render params: missing field '") + name + "'");
  return *it;
}
double Number(const nlohmann::json& j, const char* name) {
  const auto& f = Field(j, name);
  if (!f.is_number())
    throw std::invalid_argument(std::string("render params: field '") + name +
                                "' must be a number, got " + f.dump());
  return f.get<double>();
}
uint64_t Unsigned(const nlohmann::json& j, const char* name) {
  const auto& f = Field(j, name);
  if (!f.is_number_unsigned())
    throw std::invalid_argument(std::string("render params: field '") + name +
                                "' must be a non-negative integer, got " + f.dump());
  return f.get<uint64_t>();
}
int Integer(const nlohmann::json& j, const char* name) {
  const auto& f = Field(j, name);
  // Within int's range: get<int>() wrapped 4294967344 to 48 (a zeta.json rendered 48x32).
  if (!f.is_number_integer() || f.get<int64_t>() < INT32_MIN || f.get<int64_t>() > INT32_MAX)
    throw std::invalid_argument(std::string("render params: field '") + name +
                                "' must be an integer, got " + f.dump());
  return f.get<int>();
}
std::string String(const nlohmann::json& j, const char* name) {
  const auto& f = Field(j, name);
  if (!f.is_string())
    throw std::invalid_argument(std::string("render params: field '") + name +
                                "' must be a string, got " + f.dump());
  return f.get<std::string>();
}
void Require(bool ok, const char* field, const std::string& expected, double value) {
  if (!ok)
    throw std::invalid_argument(std::string("render params: field '") + field + "' is " +
                                std::to_string(value) + ", expected " + expected);
}
}  // namespace

RenderParams RenderParamsFromJson(const nlohmann::json& j) {
  RenderParams p;
  p.scene = SceneKindFromName(String(j, "scene"));
  p.seed = Unsigned(j, "seed");
  p.background_image = String(j, "background_image");
  p.background_seed = Unsigned(j, "background_seed");
  p.background_offset = Number(j, "background_offset");
  p.background_scale = Number(j, "background_scale");
  p.sun_height = Number(j, "sun_height");
  p.sun_radius = Number(j, "sun_radius");
  p.sun_azimuth_deg = Number(j, "sun_azimuth_deg");
  p.sun_strength = Number(j, "sun_strength");
  p.sun_shadow_soft_size = Number(j, "sun_shadow_soft_size");
  p.sky_strength = Number(j, "sky_strength");
  p.samples = Integer(j, "samples");
  p.camera_height = Number(j, "camera_height");
  p.camera_radius = Number(j, "camera_radius");
  p.camera_angle_deg = Number(j, "camera_angle_deg");
  p.camera_fov_deg = Number(j, "camera_fov_deg");
  p.mesh_height = Number(j, "mesh_height");
  p.mesh_width = Number(j, "mesh_width");
  p.mesh_aspect_ratio = Number(j, "mesh_aspect_ratio");
  p.texture_kind = String(j, "texture_kind");
  p.texture_name = String(j, "texture_name");
  p.texture_seed = Unsigned(j, "texture_seed");
  p.width = Integer(j, "width");
  p.height = Integer(j, "height");
  p.fps = Number(j, "fps");
  if (j.contains("look_at")) {
    const auto& a = j["look_at"];
    if (!a.is_array() || a.size() != 3 || !a[0].is_number() || !a[1].is_number() ||
        !a[2].is_number())
      throw std::invalid_argument("render params: field 'look_at' must be [x, y, z], got " +
                                  a.dump());
    p.has_look_at = true;
    for (int k = 0; k < 3; ++k) p.look_at[k] = a[k].get<double>();
  }
  ValidateRenderParams(p);
  return p;
}

void ValidateRenderParams(const RenderParams& p) {
  // At least a 0.45 m tall backdrop: a tiny scale became 0 as a float, and its texture
  // coordinates NaN.
  Require(p.background_scale >= 0.01, "background_scale", ">= 0.01", p.background_scale);
  Require(p.sun_height > 0, "sun_height", "> 0 (the sun must be above the ground)", p.sun_height);
  Require(p.sun_radius >= 0, "sun_radius", ">= 0", p.sun_radius);
  Require(p.sun_strength >= 0, "sun_strength", ">= 0", p.sun_strength);
  Require(p.sun_shadow_soft_size >= 0 && p.sun_shadow_soft_size < 90, "sun_shadow_soft_size",
          "in [0, 90) degrees", p.sun_shadow_soft_size);
  Require(p.sky_strength >= 0, "sky_strength", ">= 0", p.sky_strength);
  Require(p.samples >= 1 && p.samples <= 1024, "samples", "in [1, 1024]", p.samples);
  Require(p.camera_height > 0, "camera_height", "> 0", p.camera_height);
  // A camera (nearly) above its target looks straight down, and the camera's frame had no
  // "right": 1e-10 m failed inside the camera without naming the field.
  Require(p.camera_radius >= kMinCameraRadius, "camera_radius", ">= 0.1 m", p.camera_radius);
  Require(p.camera_fov_deg > 1 && p.camera_fov_deg < 170, "camera_fov_deg", "in (1, 170)",
          p.camera_fov_deg);
  Require(p.mesh_height >= 0, "mesh_height", ">= 0", p.mesh_height);
  Require(p.mesh_width > 0, "mesh_width", "> 0", p.mesh_width);
  Require(p.mesh_aspect_ratio > 0, "mesh_aspect_ratio", "> 0", p.mesh_aspect_ratio);
  Require(p.width > 0 && p.width <= 8192, "width", "in [1, 8192]", p.width);
  Require(p.height > 0 && p.height <= 8192, "height", "in [1, 8192]", p.height);
  Require(std::isfinite(p.fps) && p.fps > 0 && p.fps <= 1000, "fps", "in (0, 1000] Hz", p.fps);
  // Upper bounds, far beyond any scene: a value past float range (JSON takes 1e39) made infinite
  // rays that crashed Embree with the earlier render's zeta.json already removed, a huge sun
  // height rendered black frames with exit 0, and the static cache (68 B a sample) took 6 GB.
  Require(std::abs(p.background_offset) <= 1000, "background_offset", "in [-1000, 1000] m", p.background_offset);
  Require(p.background_scale <= 100, "background_scale", "<= 100", p.background_scale);
  // One Require a field: a check of two named the first with the larger value, and a user edited
  // the wrong field of a label.json.
  Require(p.sun_height <= 1e4, "sun_height", "<= 1e4 m", p.sun_height);
  Require(p.sun_radius <= 1e4, "sun_radius", "<= 1e4 m", p.sun_radius);
  Require(std::isfinite(p.sun_azimuth_deg), "sun_azimuth_deg", "finite", p.sun_azimuth_deg);
  Require(p.sun_strength <= 1e4, "sun_strength", "<= 1e4", p.sun_strength);
  Require(p.sky_strength <= 1e3, "sky_strength", "<= 1e3", p.sky_strength);
  // The ground reaches 1e6 m (the renderer's far limit): from higher than 1e3 m a band of sky
  // showed below the horizon. (At 1e3 m, rays within 0.057 deg below the horizon still pass the
  // far limit and show sky.)
  Require(p.camera_height <= 1e3, "camera_height", "<= 1000 m", p.camera_height);
  Require(p.camera_radius <= 1e4, "camera_radius", "<= 1e4 m", p.camera_radius);
  Require(std::isfinite(p.camera_angle_deg), "camera_angle_deg", "finite", p.camera_angle_deg);
  Require(p.mesh_height <= 1e3, "mesh_height", "<= 1000 m", p.mesh_height);
  Require(p.mesh_width <= 1e3, "mesh_width", "<= 1000 m", p.mesh_width);
  Require(p.mesh_aspect_ratio >= 0.1 && p.mesh_aspect_ratio <= 10, "mesh_aspect_ratio", "in [0.1, 10]",
          p.mesh_aspect_ratio);
  if (p.has_look_at)
    for (double c : p.look_at) Require(std::abs(c) <= 1e4, "look_at", "coordinates in [-1e4, 1e4] m", c);
  // The static cache holds 68 B per pixel sample: at most 2^24 of them. Named after what is too
  // big: an 8192x8192 frame is refused under width/height whatever its samples.
  constexpr double kMaxPixelSamples = 1 << 24;
  const double pixels = static_cast<double>(p.width) * p.height;
  if (pixels > kMaxPixelSamples) {
    std::ostringstream m;
    m << "render params: fields 'width' x 'height' are " << p.width << " x " << p.height
      << " = " << pixels << " pixels, expected at most 2^24 = 16.8M (the static cache holds 68 B "
      << "per pixel sample)";
    throw std::invalid_argument(m.str());
  }
  const double max_samples = std::floor(kMaxPixelSamples / pixels);
  Require(p.samples <= max_samples, "samples",
          "at most " + std::to_string(static_cast<int64_t>(max_samples)) + " for a " +
              std::to_string(p.width) + "x" + std::to_string(p.height) +
              " frame (width x height x samples at most 2^24 = 16.8M; the cache holds 68 B each)",
          p.samples);
  if (p.texture_kind == "flag")
    FlagDesignFromName(p.texture_name);
  else if (p.texture_kind == "fabric")
    FabricPatternFromName(p.texture_name);
  else
    throw std::invalid_argument("render params: field 'texture_kind' is '" + p.texture_kind +
                                "', expected 'flag' or 'fabric'");
}

}  // namespace clothwind::render
