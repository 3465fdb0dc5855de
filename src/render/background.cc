#include "render/background.h"

#include <algorithm>
#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "common/image_file.h"
#include "render/noise.h"
#include "common/random.h"

namespace clothwind::render {

bool Backdrop::Intersect(const Eigen::Vector3f& org, const Eigen::Vector3f& dir, float* t,
                         Rgb* radiance, float* alpha) const {
  const float denom = dir.dot(normal);
  if (denom > -1e-6f) return false;  // parallel or looking away from the wall
  const float tt = (origin - org).dot(normal) / denom;
  if (tt <= 0.0f) return false;
  const Eigen::Vector3f hit = org + tt * dir;
  if (hit.z() < 0.0f) return false;
  const float u = 0.5f + (hit - origin).dot(across) / width;
  const float v = hit.z() / height;
  *t = tt;
  if (v >= 1.0f) {
    *alpha = 0.0f;
    *radiance = Rgb::Zero();
    return true;
  }
  *radiance = image.Sample(u, v, Wrap::kMirror, alpha);
  return true;
}

Backdrop MakeBackdrop(const RenderParams& p, const PinholeCamera& camera) {
  Backdrop b;
  if (p.background_image.empty()) {
    b.image = ProceduralBackdrop(p.background_seed);
  } else {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p.background_image, ec))
      throw std::runtime_error("background_image '" + p.background_image + "': " +
                               (std::filesystem::exists(p.background_image, ec)
                                    ? "not a file (a folder, a pipe or a device), expected an image file"
                                    : "no such file"));
    // Whole or refused (common/image_file.h): cv::imread rendered a JPEG cut short with its
    // missing rows grey, saying only "Premature end of JPEG file" on stderr.
    std::string why;
    cv::Mat img = common::ReadImageFile(p.background_image, cv::IMREAD_COLOR, &why);
    if (img.empty())
      throw std::runtime_error("background_image '" + p.background_image + "': cannot read it as an image (" +
                               why + ")");
    b.image = Texture::FromBgr8(img);
    // Radiance that develops back to the photograph's own values.
    for (int y = 0; y < b.image.height(); ++y)
      for (int x = 0; x < b.image.width(); ++x) {
        Rgb& c = b.image.at(x, y);
        c = Rgb(InverseTone(c[0]), InverseTone(c[1]), InverseTone(c[2]));
      }
  }
  Eigen::Vector3f fwd(static_cast<float>(camera.forward.x()),
                      static_cast<float>(camera.forward.y()), 0.0f);
  if (fwd.norm() < 1e-6f) fwd = Eigen::Vector3f::UnitY();
  fwd.normalize();
  b.normal = -fwd;
  b.across = fwd.cross(Eigen::Vector3f::UnitZ()).normalized();  // image right = camera right
  const Eigen::Vector3d c = MeshCentre(p);
  const Eigen::Vector3f centre(static_cast<float>(c.x()), static_cast<float>(c.y()), 0.0f);
  b.height = Backdrop::kBackdropHeight * static_cast<float>(p.background_scale);
  b.width = b.height * static_cast<float>(b.image.width()) / b.image.height();
  b.origin = centre + Backdrop::kBackdropDistance * fwd +
             static_cast<float>(p.background_offset) * b.across;
  return b;
}

namespace {
// Display sRGB 8-bit colour to the radiance that develops to it.
Rgb Paint(float r, float g, float b) {
  return Rgb(InverseTone(SrgbToLinear(r / 255.0f)), InverseTone(SrgbToLinear(g / 255.0f)),
             InverseTone(SrgbToLinear(b / 255.0f)));
}
}  // namespace

Texture ProceduralBackdrop(uint64_t seed, int width, int height) {
  Rng rng(HashSeed(seed, 0xbac6));
  Texture t(width, height, Rgb::Zero(), 0.0f);
  const float kWidthM = 90.0f, kHeightM = 45.0f;
  const uint64_t s_hill = rng.Next(), s_tree = rng.Next(), s_leaf = rng.Next(),
                 s_grass = rng.Next();
  const bool hills = rng.Uniform() < 0.6;
  const float hill_base = static_cast<float>(rng.Uniform(4, 10));
  const float tree_base = static_cast<float>(rng.Uniform(7, 20));
  const float tree_gap = static_cast<float>(rng.Uniform(0.0, 0.45));  // fraction of open field
  const Rgb haze = Paint(200, 212, 222);
  const Rgb hill_col = Paint(95, 120, 105);
  const Rgb tree_dark = Paint(static_cast<float>(rng.Uniform(25, 45)),
                              static_cast<float>(rng.Uniform(55, 80)),
                              static_cast<float>(rng.Uniform(25, 40)));
  const Rgb tree_light = Paint(static_cast<float>(rng.Uniform(70, 110)),
                               static_cast<float>(rng.Uniform(110, 140)),
                               static_cast<float>(rng.Uniform(45, 70)));
  const Rgb field = Paint(static_cast<float>(rng.Uniform(100, 140)),
                          static_cast<float>(rng.Uniform(140, 170)),
                          static_cast<float>(rng.Uniform(70, 95)));
  struct Building {
    float x0, x1, top;
    Rgb wall, window;
  };
  std::vector<Building> buildings;
  const int n_buildings = rng.Uniform() < 0.5 ? 1 + rng.UniformInt(5) : 0;
  for (int i = 0; i < n_buildings; ++i) {
    Building b;
    b.x0 = static_cast<float>(rng.Uniform(0, kWidthM - 10));
    b.x1 = b.x0 + static_cast<float>(rng.Uniform(6, 22));
    b.top = static_cast<float>(rng.Uniform(6, 28));
    const float grey = static_cast<float>(rng.Uniform(120, 220));
    b.wall = Paint(grey * static_cast<float>(rng.Uniform(0.9, 1.1)), grey,
                   grey * static_cast<float>(rng.Uniform(0.8, 1.0)));
    b.window = Paint(60, 70, 85);
    buildings.push_back(b);
  }
  struct Crown {
    float x, r, c;  // centre [m] along the wall, radius [m], centre height [m]
  };
  std::vector<Crown> crowns;
  // Neighbouring crowns overlap (spacing below the radius), so a tree line has no slits.
  for (float x = -6.0f; x < kWidthM + 6.0f;) {
    Crown cr;
    cr.x = x;
    cr.r = static_cast<float>(rng.Uniform(2.0, 5.0));
    cr.c = tree_base + static_cast<float>(rng.Uniform(-4.0, 5.0)) - cr.r;
    crowns.push_back(cr);
    x += cr.r * static_cast<float>(rng.Uniform(0.5, 0.95));
  }
  // Silhouettes depend on the column only: compute them once per column.
  std::vector<float> hill_top(width, -1.0f), canopy(width, -1.0f), field_top(width);
  for (int x = 0; x < width; ++x) {
    const float X = (x + 0.5f) / width * kWidthM;
    if (hills) hill_top[x] = hill_base + 12.0f * FractalNoise(X / 35.0f, 0.5f, s_hill, 3);
    const float open = FractalNoise(X / 25.0f, 3.7f, s_tree + 1, 2);
    if (open > tree_gap * 0.9f + 0.05f) {
      // Rounded crowns, slightly ragged, over a dense understorey.
      float top = 0.5f * tree_base;
      for (const Crown& cr : crowns) {
        const float d = X - cr.x;
        if (std::abs(d) < cr.r) top = std::max(top, cr.c + 0.9f * std::sqrt(cr.r * cr.r - d * d));
      }
      canopy[x] = top + 0.5f * ValueNoise(X / 0.6f, 0.7f, s_tree + 2);
    }
    field_top[x] = 1.2f + 0.6f * ValueNoise(X / 4.0f, 0.2f, s_grass);
  }
  for (int y = 0; y < height; ++y) {
    const float z = (1.0f - (y + 0.5f) / height) * kHeightM;
    for (int x = 0; x < width; ++x) {
      const float X = (x + 0.5f) / width * kWidthM;
      // Near to far: the first layer that covers the texel wins.
      Rgb c = Rgb::Zero();
      float a = 1.0f;
      if (z < field_top[x]) {
        c = field * (0.85f + 0.3f * FractalNoise(X / 2.0f, z * 4.0f, s_grass + 1, 2));
      } else if (z < canopy[x]) {
        const float leaf = FractalNoise(X / 1.2f, z / 1.2f, s_leaf, 3);
        const float shade =
            std::clamp(0.15f + 0.9f * leaf + 0.35f * (z / std::max(canopy[x], 1.0f)), 0.0f, 1.0f);
        c = tree_dark + shade * (tree_light - tree_dark);
      } else {
        const Building* hit = nullptr;
        for (const Building& b : buildings)
          if (X >= b.x0 && X < b.x1 && z < b.top) hit = &b;  // later ones stand in front
        if (hit) {
          const float wx = std::fmod(X - hit->x0, 3.0f), wz = std::fmod(z, 3.2f);
          const bool window = wx > 1.0f && wx < 2.2f && wz > 1.0f && wz < 2.4f && z > 1.0f &&
                              z < hit->top - 1.0f;
          c = 0.8f * (window ? hit->window : hit->wall) + 0.2f * haze;
        } else if (z < hill_top[x]) {
          c = 0.55f * hill_col + 0.45f * haze;
        } else {
          a = 0.0f;
        }
      }
      t.at(x, y) = c;
      t.alpha(x, y) = a;
    }
  }
  return t;
}

std::vector<std::string> ListBackgroundImages(const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throw std::runtime_error("background folder '" + folder + "' " +
                             (fs::exists(folder, ec) ? "is a file, expected a folder of images" : "does not exist"));
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    if (ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".bmp")
      out.push_back(e.path().string());
  }
  if (out.empty())
    throw std::runtime_error("background folder '" + folder + "' holds no .jpg/.jpeg/.png/.bmp image");
  std::sort(out.begin(), out.end());
  // Each read whole now: one that cannot be read was found only when a simulation drew it, after
  // its simulation, and every simulation that drew it failed.
  for (const std::string& image : out) {
    std::string why;
    // Read at an eighth (quick for a folder of photos); a PNG under 8 px, which that scale makes
    // 0 px, whole (it was refused as unreadable: "inv_scale_x > 0").
    if (common::ReadImageFile(image, cv::IMREAD_REDUCED_COLOR_8, &why).empty() &&
        common::ReadImageFile(image, cv::IMREAD_COLOR, &why).empty())
      throw std::runtime_error("background folder '" + folder + "': cannot read " + image + " as an image (" + why +
                               ")");
  }
  return out;
}

}  // namespace clothwind::render
