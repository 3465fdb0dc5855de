#include "render/renderer.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "render/test_meshes.h"

namespace clothwind::render {
namespace {

// A fixed ζ for the tests (small frames keep them fast).
RenderParams TestParams() {
  RenderParams p;
  p.seed = 42;
  p.background_seed = 7;
  p.width = 120;
  p.height = 120;
  p.samples = 2;
  p.camera_height = 1.5;
  p.camera_radius = 5.0;
  p.sun_height = 8.0;
  p.sun_radius = 3.0;
  p.sun_azimuth_deg = -60.0;  // in front of the flag (camera side) and to the right
  p.sun_strength = 6.0;
  p.sun_shadow_soft_size = 0.5;
  p.texture_name = "vertical_tricolour";
  p.texture_seed = 3;
  return p;
}

Eigen::Vector3f F3(const Eigen::Vector3d& v) { return v.cast<float>(); }

float Luma(const Rgb& c) { return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2]; }

TEST(Renderer, SameParamsAndSeedGiveIdenticalBytesOnAnyThreadCount) {
  const RenderParams p = TestParams();
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.3);
  // Explicit counts: 0 (all cores) is 1 or 2 on a small test machine and proved nothing.
  RenderOptions one, three, seven;
  one.threads = 1;
  three.threads = 3;
  seven.threads = 7;
  Renderer a(p, one), b(p, three), c(p, seven);
  const cv::Mat fa = a.RenderFrame(m.V, m.F, m.UV);
  const cv::Mat fb = b.RenderFrame(m.V, m.F, m.UV);
  ASSERT_EQ(fa.type(), CV_8UC3);
  ASSERT_EQ(fa.rows, 120);
  ASSERT_EQ(fa.cols, 120);
  EXPECT_EQ(cv::norm(fa, fb, cv::NORM_INF), 0.0);
  // Radiance too, bit for bit (8-bit frames hide differences below a level).
  const cv::Mat la = a.RenderLinear(m.V, m.F, m.UV), lc = c.RenderLinear(m.V, m.F, m.UV);
  EXPECT_EQ(cv::norm(la, lc, cv::NORM_INF), 0.0);
  // Another pixel-sampling seed moves anti-aliasing and penumbra samples only a little: a few
  // edge pixels change, the rest of the frame (backdrop, ground, the flag's interior) not at all.
  // Another background seed redraws the backdrop and the grass. Two views: the usual one (the
  // flag against the backdrop, little ground) and one looking down at the grass, so that a
  // backdrop or a grass texture seeded from the pixel seed shows in one of them. Only "differs"
  // was asserted before, which a pixel seed that redrew the whole background passed.
  RenderParams ground_p = p;
  ground_p.width = ground_p.height = 80;
  ground_p.samples = 1;  // no jitter: the grass is all texture edges, where 2 samples differ
  ground_p.camera_height = 6.0;
  ground_p.has_look_at = true;
  ground_p.look_at[0] = 1.0;
  ground_p.look_at[1] = -4.0;
  ground_p.look_at[2] = 0.0;
  for (const RenderParams& view : {p, ground_p}) {
    SCOPED_TRACE(view.has_look_at ? "looking down at the grass" : "the usual view");
    const cv::Mat base = view.has_look_at ? Renderer(view).RenderFrame(m.V, m.F, m.UV) : fa;
    // Mean absolute difference per channel [8-bit levels] and fraction of pixels that differ.
    auto compare = [&](const RenderParams& other, double* mean, double* changed) {
      const cv::Mat f = Renderer(other).RenderFrame(m.V, m.F, m.UV);
      cv::Mat diff;
      cv::absdiff(base, f, diff);
      const double pixels = static_cast<double>(diff.total());
      *mean = cv::norm(diff, cv::NORM_L1) / (3.0 * pixels);
      cv::Mat any;
      cv::transform(diff, any, cv::Matx13f(1, 1, 1));
      *changed = cv::countNonZero(any) / pixels;
    };
    double mean, changed;
    RenderParams q = view;
    q.seed = view.seed + 1;
    compare(q, &mean, &changed);
    if (!view.has_look_at) {
      EXPECT_GT(changed, 0.0);  // the seed is used
    }
    EXPECT_LT(changed, 0.10);    // edge pixels only (~3.6 % in the usual view, ~0.03 % on the grass)
    EXPECT_LT(mean, 2.0);        // ~1 level in the usual view, ~0.02 on the grass
    q = view;
    q.background_seed = view.background_seed + 1;
    compare(q, &mean, &changed);
    EXPECT_GT(changed, 0.25);    // the backdrop or the grass everywhere (~37 %, and ~100 % on the grass)
    EXPECT_GT(mean, 5.0);        // ~13 levels in the usual view, ~7 on the grass
  }
  // Another texture seed recolours the flag.
  RenderParams q = p;
  q.texture_seed = 4;
  const cv::Mat fd = Renderer(q).RenderFrame(m.V, m.F, m.UV);
  EXPECT_GT(cv::norm(fa, fd, cv::NORM_L1) / (120.0 * 120.0), 1.0);
}

TEST(Renderer, FlagCentreIsInTheMiddleOfTheFrame) {
  const RenderParams p = TestParams();
  Renderer r(p);
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.0, /*amplitude=*/0.0);
  r.RenderLinear(m.V, m.F, m.UV);
  // The camera ray through the image centre meets the cloth near the flag's centre.
  Hit hit;
  const Eigen::Vector3f dir = F3(r.camera().RayDirection(60.0, 60.0));
  ASSERT_TRUE(r.scene().Intersect(F3(r.camera().position), dir, 1e4f, &hit));
  EXPECT_EQ(hit.surface, Surface::kCloth);
  // The test flag droops 0.12 h at the fly end, so allow a few centimetres.
  EXPECT_NEAR(hit.point.x(), 1.5, 0.1);
  EXPECT_NEAR(hit.point.z(), 5.6, 0.15);
}

TEST(Renderer, PointInTheFlagsShadowIsDarkerOnlyWithShadows) {
  RenderParams p = TestParams();
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.0, /*amplitude=*/0.0);
  RenderOptions on, off;
  off.shadows = false;
  Renderer with(p, on), without(p, off);
  with.RenderLinear(m.V, m.F, m.UV);
  without.RenderLinear(m.V, m.F, m.UV);
  // The ground point where the flag's centre casts its shadow (sun disc centre).
  const Eigen::Vector3f sun = with.lighting().sun_dir;
  const Eigen::Vector3f centre(1.5f, 0.0f, 5.5f);
  const Eigen::Vector3f g = centre - sun * (centre.z() / sun.z());
  const Eigen::Vector3f org = g + Eigen::Vector3f(0, 0, 0.5f), down(0, 0, -1);
  const Rgb shadowed = with.Trace(org, down, 0.0f, 0.0f);
  const Rgb lit = without.Trace(org, down, 0.0f, 0.0f);
  EXPECT_LT(Luma(shadowed), 0.6f * Luma(lit));
  // Without shadows the point is exactly as bright as with the flag moved out of the way.
  ClothMesh far = m;
  far.V.col(0).array() += 200.0;
  Renderer moved(p, on);
  moved.RenderLinear(far.V, far.F, far.UV);
  EXPECT_NEAR(Luma(moved.Trace(org, down, 0.0f, 0.0f)), Luma(lit), 1e-6f);
  // And a point far from any shadow is the same either way.
  const Eigen::Vector3f org2(-6.0f, -3.0f, 0.5f);
  EXPECT_NEAR(Luma(with.Trace(org2, down, 0.0f, 0.0f)), Luma(without.Trace(org2, down, 0.0f, 0.0f)),
              1e-7f);
}

TEST(Renderer, PointInThePolesShadowIsDarkerOnlyWithShadows) {
  RenderParams p = TestParams();
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.0, 0.0);
  RenderOptions off;
  off.shadows = false;
  Renderer with(p), without(p, off);
  with.RenderLinear(m.V, m.F, m.UV);
  without.RenderLinear(m.V, m.F, m.UV);
  const Eigen::Vector3f sun = with.lighting().sun_dir;
  const Eigen::Vector3f on_pole(-0.035f, 0.0f, 1.5f);  // pole axis, below the flag
  const Eigen::Vector3f g = on_pole - sun * (on_pole.z() / sun.z());
  const Eigen::Vector3f org = g + Eigen::Vector3f(0, 0, 0.3f), down(0, 0, -1);
  EXPECT_LT(Luma(with.Trace(org, down, 0.0f, 0.0f)), 0.6f * Luma(without.Trace(org, down, 0.0f, 0.0f)));
}

TEST(Renderer, BackFaceIsLitNotBlack) {
  RenderParams p = TestParams();
  // The sun on the front (-y) side, then at its mirror image on the back: the back face under the
  // mirrored sun must look as the front did under the first (the scene is mirror-symmetric about
  // the flag's plane). A sun overhead lit neither face (n.l = 0) and compared the sky's light only.
  p.sun_radius = 5.0;
  p.sun_azimuth_deg = -90.0;
  p.sun_height = 5.0;
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.0, 0.0);
  Renderer r(p);
  r.RenderLinear(m.V, m.F, m.UV);
  RenderParams mirrored_p = p;
  mirrored_p.sun_azimuth_deg = 90.0;
  Renderer mirrored(mirrored_p);
  mirrored.RenderLinear(m.V, m.F, m.UV);
  const Eigen::Vector3f target(1.0f, 0.0f, 5.6f);
  const Eigen::Vector3f front_org = target + Eigen::Vector3f(0, -3, 0);
  const Eigen::Vector3f back_org = target + Eigen::Vector3f(0, 3, 0);
  Hit hf, hb;
  ASSERT_TRUE(r.scene().Intersect(front_org, Eigen::Vector3f(0, 1, 0), 10.0f, &hf));
  ASSERT_TRUE(r.scene().Intersect(back_org, Eigen::Vector3f(0, -1, 0), 10.0f, &hb));
  ASSERT_EQ(hf.surface, Surface::kCloth);
  ASSERT_EQ(hb.surface, Surface::kCloth);
  EXPECT_NE(hf.back_face, hb.back_face);
  EXPECT_GT(hb.normal.y(), 0.99f);  // shading normal turned towards the viewer
  const Rgb front = r.Trace(front_org, Eigen::Vector3f(0, 1, 0), 0.5f, 0.5f);
  const Rgb back = mirrored.Trace(back_org, Eigen::Vector3f(0, -1, 0), 0.5f, 0.5f);
  const Rgb front_unlit = mirrored.Trace(front_org, Eigen::Vector3f(0, 1, 0), 0.5f, 0.5f);
  EXPECT_GT(Luma(front), 1.5f * Luma(front_unlit));  // the sun's term counts
  EXPECT_NEAR(Luma(back), Luma(front), 1e-4f * Luma(front));
  // With the sun on the front side the back is darker, but still lit (sky, translucency).
  p.sun_radius = 5.0;
  p.sun_azimuth_deg = -90.0;  // sun on -y, the front
  p.sun_height = 5.0;
  Renderer r2(p);
  r2.RenderLinear(m.V, m.F, m.UV);
  const Rgb front2 = r2.Trace(front_org, Eigen::Vector3f(0, 1, 0), 0.5f, 0.5f);
  const Rgb back2 = r2.Trace(back_org, Eigen::Vector3f(0, -1, 0), 0.5f, 0.5f);
  EXPECT_GT(Luma(front2), 1.5f * Luma(back2));
  EXPECT_GT(Luma(back2), 0.05f);
}

// The sun's term is irradiance x n.l: on a level surface (n = z) its radiance is albedo / pi x
// sun_irradiance x sin(elevation). With no sky (sky_strength 0) and n = z the ambient term is 0
// (an upward face sees no ground bounce), shadows off, no translucency: the sun's term is all the
// light, and Trace's radiance (linear, before the film's response) is checked against it, on the
// cloth (ShadeCloth) and on the ground (ComputeStatic), at two elevations. The other tests compare
// brighter and darker only: a weight of 1 for any sun above the surface's horizon passed them.
TEST(Renderer, SunLightFollowsTheCosineOfItsIncidence) {
  RenderParams p = TestParams();
  p.sky_strength = 0.0;
  p.sun_shadow_soft_size = 0.0;
  p.sun_radius = 5.0;
  // A level 2 m x 2 m cloth 1 m above the mesh's base, away from the pole.
  ClothMesh m;
  m.V.resize(4, 3);
  m.V << 0.5, -1, 1, 2.5, -1, 1, 2.5, 1, 1, 0.5, 1, 1;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  m.UV.resize(4, 2);
  m.UV << 0, 0, 1, 0, 1, 1, 0, 1;
  RenderOptions o;
  o.shadows = false;
  o.translucency = 0.0f;
  const Eigen::Vector3f down(0, 0, -1);
  const Eigen::Vector3f above_cloth(1.3f, 0.1f, static_cast<float>(p.mesh_height) + 3.0f);
  const Eigen::Vector3f above_ground(-6.0f, -3.0f, 0.5f);
  float cloth[2], ground[2], sin_elevation[2];
  int k = 0;
  for (const double sun_height : {5.0, 1.5}) {  // 45 deg and 16.7 deg up
    SCOPED_TRACE("sun height " + std::to_string(sun_height));
    p.sun_height = sun_height;
    Renderer r(p, o);
    r.RenderLinear(m.V, m.F, m.UV);
    const Lighting& l = r.lighting();
    sin_elevation[k] = static_cast<float>(sun_height / std::hypot(5.0, sun_height));
    ASSERT_NEAR(l.sun_dir.z(), sin_elevation[k], 1e-6f);
    Hit hit;
    ASSERT_TRUE(r.scene().Intersect(above_cloth, down, 10.0f, &hit));
    ASSERT_EQ(hit.surface, Surface::kCloth);
    ASSERT_NEAR(hit.normal.z(), 1.0f, 1e-6f);
    const Rgb c = r.Trace(above_cloth, down, 0.5f, 0.5f);
    const Rgb albedo = r.cloth_texture().Sample(hit.uv.x(), hit.uv.y(), Wrap::kClamp);
    const Rgb expected = (static_cast<float>(1.0 / M_PI) * sin_elevation[k]) * albedo.cwiseProduct(l.sun_irradiance);
    ASSERT_GT(Luma(expected), 0.05f);
    EXPECT_LT((c - expected).cwiseAbs().maxCoeff(), 1e-5f * expected.maxCoeff()) << c.transpose() << " vs "
                                                                                  << expected.transpose();
    cloth[k] = Luma(c);
    ASSERT_TRUE(r.scene().Intersect(above_ground, down, 10.0f, &hit));
    ASSERT_EQ(hit.surface, Surface::kGround);
    ground[k] = Luma(r.Trace(above_ground, down, 0.5f, 0.5f));
    ASSERT_GT(ground[k], 0.0f);
    ++k;
  }
  // The same point under both suns: the albedo cancels, the cosine ratio remains (~2.44 here).
  const float cos_ratio = sin_elevation[0] / sin_elevation[1];
  EXPECT_NEAR(cloth[0] / cloth[1], cos_ratio, 1e-5f * cos_ratio);
  EXPECT_NEAR(ground[0] / ground[1], cos_ratio, 1e-5f * cos_ratio);
}

// A fold of two faces meeting at the hoist, the sun grazing from behind the face the camera sees
// while that face's smoothed normal (bent by the other face) turns toward it: smooth shading
// lights the point, and the shadow ray must leave from the triangle's sunny side. It left from
// the normal's side, met its own triangle, and single triangles of a flag went dark.
TEST(Renderer, ASunGrazingBehindAFacetLightsItsSmoothSide) {
  RenderParams p = TestParams();
  p.sun_azimuth_deg = 11.3;  // along +x, a little behind the face (+y)
  p.sun_radius = 5.0;
  p.sun_height = 3.0;
  p.sun_shadow_soft_size = 0.0;
  // Top view: face A from the edge (x = y = 0) along +x, facing -y (the camera); face B from the
  // edge toward (-cos 60 deg, -sin 60 deg). 2 m high; two triangles each, consistently wound.
  ClothMesh m;
  const double bx = -0.5, by = -0.8660254;
  m.V.resize(6, 3);
  m.V << 0, 0, 0, 1, 0, 0, bx, by, 0, 0, 0, 2, 1, 0, 2, bx, by, 2;
  m.F.resize(4, 3);
  m.F << 0, 1, 4, 0, 4, 3, 2, 0, 3, 2, 3, 5;
  m.UV.resize(6, 2);
  m.UV << 0.5, 0, 1, 0, 0, 0, 0.5, 1, 1, 1, 0, 1;
  RenderOptions off;
  off.shadows = false;
  Renderer with(p), without(p, off);
  with.RenderLinear(m.V, m.F, m.UV);
  without.RenderLinear(m.V, m.F, m.UV);
  const Eigen::Vector3f org(0.05f, -3.0f, static_cast<float>(p.mesh_height) + 1.0f), dir(0, 1, 0);
  Hit hit;
  ASSERT_TRUE(with.scene().Intersect(org, dir, 10.0f, &hit));
  ASSERT_EQ(hit.surface, Surface::kCloth);
  const Eigen::Vector3f sun = with.lighting().sun_dir;
  ASSERT_GT(hit.normal.dot(sun), 0.1f) << "the smoothed normal must face the sun";
  ASSERT_LT(hit.geom_normal.dot(sun), -0.1f) << "the facet must face away from it";
  const float lit = Luma(without.Trace(org, dir, 0.5f, 0.5f));
  EXPECT_NEAR(Luma(with.Trace(org, dir, 0.5f, 0.5f)), lit, 1e-6f * lit);
  // And the sun's term is there to lose: without the sun the point is darker.
  RenderParams dark_p = p;
  dark_p.sun_strength = 0.0;
  Renderer dark(dark_p, off);
  dark.RenderLinear(m.V, m.F, m.UV);
  EXPECT_GT(lit, 1.2f * Luma(dark.Trace(org, dir, 0.5f, 0.5f)));
}

// The cached path with shadows: each frame's cached static sample (its shadow ray's origin, whether
// it sees the sun) and the per-frame test of whether the cloth blocks the sun give what a
// direct trace gives, over two frames whose flag shadows different ground. A sun disc of size 0,
// so that a sample does not depend on its point of the disc.
TEST(Renderer, CachedFramesWithShadowsMatchUncachedTrace) {
  RenderParams p = TestParams();
  p.samples = 1;
  p.sun_shadow_soft_size = 0.0;
  // The camera looks down at the ground where the flag's centre casts its shadow.
  const Eigen::Vector3f sun = Renderer(p).lighting().sun_dir;
  const Eigen::Vector3f centre(1.5f, 0.0f, 5.5f);
  const Eigen::Vector3f g = centre - sun * (centre.z() / sun.z());
  p.camera_height = 6.0;
  p.has_look_at = true;
  p.look_at[0] = g.x();
  p.look_at[1] = g.y();
  p.look_at[2] = g.z();
  Renderer r(p);
  RenderOptions off;
  off.shadows = false;
  Renderer unshadowed(p, off);
  int in_shadow = 0;
  for (double t : {0.0, 0.37}) {
    const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, t);
    const cv::Mat img = r.RenderLinear(m.V, m.F, m.UV);
    unshadowed.RenderLinear(m.V, m.F, m.UV);
    for (int y = 2; y < 120; y += 7)
      for (int x = 1; x < 120; x += 7) {
        const Eigen::Vector3f o = F3(r.camera().position), d = F3(r.camera().RayDirection(x + 0.5, y + 0.5));
        const Rgb c = r.Trace(o, d, 0.3f, 0.3f);
        const cv::Vec3f v = img.at<cv::Vec3f>(y, x);
        EXPECT_NEAR(v[0], c[0], 1e-5f) << x << "," << y << " t=" << t;
        EXPECT_NEAR(v[1], c[1], 1e-5f);
        EXPECT_NEAR(v[2], c[2], 1e-5f);
        in_shadow += Luma(c) < 0.9f * Luma(unshadowed.Trace(o, d, 0.3f, 0.3f));
      }
  }
  EXPECT_GT(in_shadow, 5) << "the sampled pixels must include shadowed ones";
}

TEST(Renderer, CachedFramesMatchUncachedTraceAcrossFrames) {
  RenderParams p = TestParams();
  p.samples = 1;
  RenderOptions o;
  o.shadows = false;  // then a sample does not depend on its sun-disc point
  Renderer r(p, o);
  for (double t : {0.0, 0.37}) {
    const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, t);
    const cv::Mat img = r.RenderLinear(m.V, m.F, m.UV);
    for (int y = 5; y < 120; y += 23)
      for (int x = 3; x < 120; x += 19) {
        const Rgb c = r.Trace(F3(r.camera().position),
                              F3(r.camera().RayDirection(x + 0.5, y + 0.5)), 0.3f, 0.3f);
        const cv::Vec3f v = img.at<cv::Vec3f>(y, x);
        EXPECT_NEAR(v[0], c[0], 1e-5f) << x << "," << y << " t=" << t;
        EXPECT_NEAR(v[1], c[1], 1e-5f);
        EXPECT_NEAR(v[2], c[2], 1e-5f);
      }
  }
}

// Several samples a pixel, with shadows and a sun disc: each pixel is its centre sample (one
// sample is the answer away from edges) or the mean of its jittered ones, each traced along
// PixelSampleAt's ray to its point of the sun. The tests above take one sample, so a cache
// indexed wrongly across samples, or samples given each other's sun points, passed them.
TEST(Renderer, CachedFramesWithManySamplesMatchUncachedTrace) {
  RenderParams p = TestParams();
  p.samples = 4;
  p.sun_shadow_soft_size = 8.0;  // penumbrae: the sun point of each sample counts
  const Eigen::Vector3f sun = Renderer(p).lighting().sun_dir;
  const Eigen::Vector3f centre(1.5f, 0.0f, 5.5f);
  const Eigen::Vector3f g = centre - sun * (centre.z() / sun.z());
  p.camera_height = 6.0;  // looking down at the flag's shadow, the flag in view too
  p.has_look_at = true;
  p.look_at[0] = 0.5 * (g.x() + centre.x());
  p.look_at[1] = 0.5 * (g.y() + centre.y());
  p.look_at[2] = 0.5 * (g.z() + centre.z());
  p.width = p.height = 60;
  Renderer r(p);
  int edges = 0;
  for (double t : {0.0, 0.37}) {
    const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, t);
    const cv::Mat img = r.RenderLinear(m.V, m.F, m.UV);
    const Eigen::Vector3f o = F3(r.camera().position);
    for (int y = 0; y < p.height; ++y)
      for (int x = 0; x < p.width; ++x) {
        Rgb samples[4];
        for (int s = 0; s < 4; ++s) {
          const PixelSample ps = PixelSampleAt(p.seed, x, y, s);
          samples[s] = r.Trace(o, F3(r.camera().RayDirection(x + ps.jx, y + ps.jy)), ps.su, ps.sv);
        }
        const Rgb jittered = (samples[1] + samples[2] + samples[3]) / 3.0f;
        const cv::Vec3f v = img.at<cv::Vec3f>(y, x);
        const Rgb got(v[0], v[1], v[2]);
        const bool is_centre = (got - samples[0]).cwiseAbs().maxCoeff() < 1e-5f;
        const bool is_mean = (got - jittered).cwiseAbs().maxCoeff() < 1e-5f;
        EXPECT_TRUE(is_centre || is_mean) << x << "," << y << " t=" << t;
        edges += !is_centre && is_mean;
      }
  }
  EXPECT_GT(edges, 50) << "the frames must have edge pixels, where the jittered samples count";
}

// The ground is a plane to the horizon: from a camera 700 m from the flag (ζ allows 1e4 m) the
// rays below the horizon met nothing past the ground's 500 m triangles, and half the frame was sky.
TEST(EmbreeScene, GroundReachesPastItsTriangles) {
  const EmbreeScene scene(TestParams());
  const Eigen::Vector3f org(0.0f, -700.0f, 3.0f), dir = Eigen::Vector3f(0, 1, -0.02f).normalized();
  Hit hit;
  ASSERT_TRUE(scene.IntersectStatic(org, dir, 1e4f, &hit));
  EXPECT_EQ(hit.surface, Surface::kGround);
  EXPECT_NEAR(hit.point.y(), -700.0f + 150.0f, 0.01f);
  EXPECT_EQ(hit.point.z(), 0.0f);
  EXPECT_EQ(hit.normal, Eigen::Vector3f::UnitZ());
  EXPECT_NEAR(hit.t, 150.0f * std::sqrt(1.0004f), 0.01f);  // 3 m down at 0.02 m a metre
  ASSERT_TRUE(scene.Intersect(org, dir, 1e4f, &hit));
  EXPECT_EQ(hit.surface, Surface::kGround);
  EXPECT_TRUE(scene.Occluded(org, dir, 1e4f));
  EXPECT_TRUE(scene.OccludedStatic(org, dir, 1e4f));
  // Not before t_max, not upwards, not from below.
  EXPECT_FALSE(scene.IntersectStatic(org, dir, 100.0f, &hit));
  EXPECT_FALSE(scene.OccludedStatic(org, dir, 100.0f));
  EXPECT_FALSE(scene.IntersectStatic(org, Eigen::Vector3f(0, 1, 0.02f).normalized(), 1e4f, &hit));
  EXPECT_FALSE(scene.IntersectStatic(Eigen::Vector3f(0, -700, -1), dir, 1e4f, &hit));
}

// Far away, or high above the backdrop's hills (100 m up, looking down past its transparent top,
// where the sky showed: the ground beyond it shows now).
class FarCamera : public ::testing::TestWithParam<std::pair<double, double>> {};

TEST_P(FarCamera, SeesGroundBelowTheHorizon) {
  RenderParams p = TestParams();
  p.samples = 1;
  p.width = p.height = 40;
  p.camera_radius = GetParam().first;
  p.camera_height = GetParam().second;
  Renderer r(p);
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.0);
  const cv::Mat img = r.RenderLinear(m.V, m.F, m.UV);
  int below = 0;
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) {
      const Eigen::Vector3f d = F3(r.camera().RayDirection(x + 0.5, y + 0.5));
      if (d.z() > -0.002f) continue;  // the horizon and above
      ++below;
      const cv::Vec3f v = img.at<cv::Vec3f>(y, x);
      const Rgb sky = r.lighting().SkyRadiance(d);
      EXPECT_GT((Rgb(v[0], v[1], v[2]) - sky).cwiseAbs().maxCoeff(), 1e-3f)
          << "sky below the horizon at " << x << "," << y;
    }
  EXPECT_GT(below, 300);
}

INSTANTIATE_TEST_SUITE_P(Renderer, FarCamera,
                         ::testing::Values(std::pair{700.0, 3.0}, std::pair{60.0, 100.0}));

// The backdrop over what lies behind it, by its coverage (hand-worked values): the premultiplied
// colour plus (1 - alpha) of what shows through, the sun only on that part, and the backdrop
// counted as seen where it covers more than half.
TEST(Renderer, TheBackdropCoversWhatIsBehindItByItsAlpha) {
  Renderer::StaticSample ground;
  ground.base = Rgb(0.2f, 0.4f, 0.1f);
  ground.sunlit = Rgb(1.0f, 0.8f, 0.6f);
  ground.can_see_sun = true;
  ground.shadow_org = Eigen::Vector3f(5, 6, 0);
  ground.what = Renderer::kGroundSeen;
  ground.t = 90.0f;
  const Rgb colour(0.05f, 0.1f, 0.15f);  // premultiplied by alpha 0.25
  const Renderer::StaticSample quarter = Renderer::OverBackdrop(colour, 0.25f, 40.0f, ground);
  EXPECT_NEAR(quarter.base.x(), 0.05f + 0.75f * 0.2f, 1e-6f);
  EXPECT_NEAR(quarter.base.y(), 0.1f + 0.75f * 0.4f, 1e-6f);
  EXPECT_NEAR(quarter.base.z(), 0.15f + 0.75f * 0.1f, 1e-6f);
  EXPECT_TRUE(quarter.can_see_sun);
  EXPECT_NEAR(quarter.sunlit.x(), 0.75f, 1e-6f);
  EXPECT_NEAR(quarter.sunlit.z(), 0.45f, 1e-6f);
  EXPECT_EQ(quarter.shadow_org, ground.shadow_org);  // the shadow is the ground's
  EXPECT_EQ(quarter.what, Renderer::kGroundSeen);     // mostly ground
  EXPECT_EQ(quarter.t, 40.0f);                        // the backdrop is what the ray meets first
  const Renderer::StaticSample most = Renderer::OverBackdrop(colour, 0.75f, 40.0f, ground);
  EXPECT_EQ(most.what, Renderer::kBackdrop);
  EXPECT_NEAR(most.sunlit.y(), 0.25f * 0.8f, 1e-6f);
  // Opaque: the backdrop alone, its colour as filtered, no sun through it.
  const Renderer::StaticSample opaque = Renderer::OverBackdrop(colour, 1.0f, 40.0f, ground);
  EXPECT_EQ(opaque.base, colour);
  EXPECT_FALSE(opaque.can_see_sun);
  EXPECT_EQ(opaque.sunlit, Rgb::Zero());
  // Transparent over the sky: the sky as it is (no sun term to carry).
  Renderer::StaticSample sky;
  sky.base = Rgb(0.3f, 0.5f, 0.9f);
  sky.what = Renderer::kSky;
  const Renderer::StaticSample clear = Renderer::OverBackdrop(Rgb::Zero(), 0.0f, 40.0f, sky);
  EXPECT_EQ(clear.base, sky.base);
  EXPECT_FALSE(clear.can_see_sun);
  EXPECT_EQ(clear.what, Renderer::kSky);
}

// A SetCloth refused half way (a bad index in its last face) leaves the previous cloth: it
// rewrote the faces up to the bad one while Embree kept the old geometry, so hits read the new
// faces' vertices (here: the old ones in another order, other texture coordinates).
TEST(EmbreeScene, RefusedClothLeavesThePreviousOne) {
  Renderer r(TestParams());
  const ClothMesh a = WavingFlag(25, 17, 3.0, 2.0, 0.1);
  r.RenderLinear(a.V, a.F, a.UV);
  const Eigen::Vector3f org(1.2f, -3.0f, 5.3f), dir(0, 1, 0);
  Hit before, after;
  ASSERT_TRUE(r.scene().Intersect(org, dir, 10.0f, &before));
  ASSERT_EQ(before.surface, Surface::kCloth);
  const Rgb traced = r.Trace(org, dir, 0.5f, 0.5f);
  const Eigen::AlignedBox3f bounds = r.scene().cloth_bounds();

  ClothMesh b = a;
  for (int f = 0; f < b.F.rows(); ++f) b.F.row(f) << a.F(f, 1), a.F(f, 2), a.F(f, 0);
  b.F(b.F.rows() - 1, 2) = static_cast<int>(b.V.rows()) + 5;
  b.V.array() += 0.5;
  EXPECT_THROW(r.RenderLinear(b.V, b.F, b.UV), std::invalid_argument);

  ASSERT_TRUE(r.scene().Intersect(org, dir, 10.0f, &after));
  EXPECT_EQ(after.surface, Surface::kCloth);
  EXPECT_EQ(after.t, before.t);
  EXPECT_EQ(after.uv, before.uv);
  EXPECT_EQ(after.normal, before.normal);
  EXPECT_TRUE(r.scene().cloth_bounds().isApprox(bounds));
  const Rgb again = r.Trace(org, dir, 0.5f, 0.5f);
  EXPECT_EQ(again, traced);
}

std::string SetClothError(EmbreeScene* scene, const ClothMesh& m) {
  try {
    scene->SetCloth(m.V, m.F, m.UV);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

// Non-finite coordinates are refused naming the vertex and the coordinate: 1e39 is finite as a
// double and became inf as a float, and NaN texture coordinates reached float-to-int conversions.
TEST(EmbreeScene, NonFiniteVerticesAndTextureCoordinatesAreRefused) {
  EmbreeScene scene(TestParams());
  const ClothMesh good = WavingFlag(5, 4);
  scene.SetCloth(good.V, good.F, good.UV);
  const Eigen::AlignedBox3f bounds = scene.cloth_bounds();
  ClothMesh m = good;
  m.V(7, 1) = 1e39;
  std::string e = SetClothError(&scene, m);
  EXPECT_NE(e.find("vertex 7 has V coordinate y = 1e+39"), std::string::npos) << e;
  m = good;
  m.V(2, 2) = std::numeric_limits<double>::quiet_NaN();
  e = SetClothError(&scene, m);
  EXPECT_NE(e.find("vertex 2 has V coordinate z = nan"), std::string::npos) << e;
  m = good;
  m.V(4, 0) = 2e6;  // finite, but the normals' cross products overflow soon after
  e = SetClothError(&scene, m);
  EXPECT_NE(e.find("vertex 4 has V coordinate x = 2e+06"), std::string::npos) << e;
  EXPECT_NE(e.find("within +-1e+06 m"), std::string::npos) << e;
  m = good;
  m.UV(3, 0) = std::numeric_limits<double>::quiet_NaN();
  e = SetClothError(&scene, m);
  EXPECT_NE(e.find("vertex 3 has UV coordinate u = nan"), std::string::npos) << e;
  m = good;
  m.UV(5, 1) = -std::numeric_limits<double>::infinity();
  e = SetClothError(&scene, m);
  EXPECT_NE(e.find("vertex 5 has UV coordinate v = -inf"), std::string::npos) << e;
  EXPECT_TRUE(scene.cloth_bounds().isApprox(bounds));  // still the good cloth
}

// A device that cannot be made says why (the reason was dropped), and nothing leaks on the way
// out (the handles release what was made before the throw).
TEST(EmbreeScene, DeviceErrorsAreNamed) {
  try {
    EmbreeScene scene(TestParams(), "threads=not-a-number");
    FAIL() << "a bad device configuration was accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("threads=not-a-number"), std::string::npos) << what;
    EXPECT_NE(what.find("RTC_ERROR_"), std::string::npos) << what;
  }
}

TEST(Renderer, NewFacesRebuildTheClothAndMatchAFreshRenderer) {
  const RenderParams p = TestParams();
  const ClothMesh a = WavingFlag(25, 17, 3.0, 2.0, 0.1);
  const ClothMesh b = WavingFlag(14, 9, 3.0, 2.0, 0.2);
  Renderer r(p);
  r.RenderFrame(a.V, a.F, a.UV);
  const cv::Mat second = r.RenderFrame(b.V, b.F, b.UV);
  const cv::Mat fresh = Renderer(p).RenderFrame(b.V, b.F, b.UV);
  EXPECT_EQ(cv::norm(second, fresh, cv::NORM_INF), 0.0);
}

TEST(Renderer, BadMeshIsRejectedWithAClearError) {
  Renderer r(TestParams());
  ClothMesh m = WavingFlag(5, 4);
  Eigen::MatrixXd uv = m.UV.topRows(3);
  EXPECT_THROW(r.RenderLinear(m.V, m.F, uv), std::invalid_argument);
  m.F(0, 1) = 999;
  try {
    r.RenderLinear(m.V, m.F, m.UV);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("999"), std::string::npos) << e.what();
  }
}

// An edge pixel's value is the mean of its jittered samples, which does not lean towards what the
// pixel centre sees. With the centre among the 4 samples (weight 1/4) the error of a 4-sample
// pixel against the converged value grew with the centre's own error: slope 0.25 (coverage 0.30
// for a true 0.43 along a flag's top edge).
TEST(Renderer, EdgePixelsDoNotLeanTowardsTheirCentreSample) {
  RenderParams p = TestParams();
  const ClothMesh m = WavingFlag(25, 17, 3.0, 2.0, 0.0, /*amplitude=*/0.0);
  const auto render = [&](int samples) {
    p.samples = samples;
    return Renderer(p).RenderLinear(m.V, m.F, m.UV);
  };
  const cv::Mat centre = render(1), four = render(4), converged = render(256);
  double d1d4 = 0, d1d1 = 0;
  int edges = 0;
  for (int y = 0; y < centre.rows; ++y) {
    for (int x = 0; x < centre.cols; ++x) {
      const cv::Vec3f c = centre.at<cv::Vec3f>(y, x), f = four.at<cv::Vec3f>(y, x), t = converged.at<cv::Vec3f>(y, x);
      if (c == f) continue;  // not an edge: one sample is the answer
      const double d1 = Luma(Rgb(c[0] - t[0], c[1] - t[1], c[2] - t[2]));
      const double d4 = Luma(Rgb(f[0] - t[0], f[1] - t[1], f[2] - t[2]));
      d1d4 += d1 * d4;
      d1d1 += d1 * d1;
      ++edges;
    }
  }
  ASSERT_GT(edges, 100);
  EXPECT_LT(std::abs(d1d4 / d1d1), 0.1) << edges << " edge pixels";
}

TEST(Backdrop, PhotographComesOutAsItself) {
  const std::string dir = testing::TempDir() + "/render_bg_test_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  const std::string file = dir + "/wall.png";
  // Four quadrants of their own colours (B, G, R): a photo of one colour came out as itself upside
  // down or mirrored too.
  const cv::Scalar top_left(40, 120, 200), top_right(200, 40, 120), bottom_left(120, 200, 40), bottom_right(90, 60, 30);
  cv::Mat photo(60, 120, CV_8UC3);
  photo(cv::Rect(0, 0, 60, 30)).setTo(top_left);
  photo(cv::Rect(60, 0, 60, 30)).setTo(top_right);
  photo(cv::Rect(0, 30, 60, 30)).setTo(bottom_left);
  photo(cv::Rect(60, 30, 60, 30)).setTo(bottom_right);
  ASSERT_TRUE(cv::imwrite(file, photo));
  const std::vector<std::string> files = ListBackgroundImages(dir);
  ASSERT_EQ(files.size(), 1u);
  RenderParams p = TestParams();
  p.background_image = files[0];
  p.background_offset = 13.0;
  p.background_scale = 0.7;
  Renderer r(p);
  const Backdrop& b = r.backdrop();
  EXPECT_NEAR(b.height, 0.7f * Backdrop::kBackdropHeight, 1e-4f);
  EXPECT_NEAR(b.width, 2.0f * b.height, 1e-3f);
  // The picture's centre moved 13 m sideways, along the camera's right.
  const Eigen::Vector3d c = MeshCentre(p);
  const Eigen::Vector3f foot(static_cast<float>(c.x()), static_cast<float>(c.y()), 0.0f);
  EXPECT_NEAR((b.origin - foot).dot(b.across), 13.0f, 1e-3f);
  EXPECT_NEAR((b.origin - foot).dot(-b.normal), Backdrop::kBackdropDistance, 1e-3f);
  // The photo's right is the camera's right, its top is up: each quadrant's centre shows its colour.
  EXPECT_GT(b.across.dot(F3(r.camera().right)), 0.99f);
  const Eigen::Vector3f cam = F3(r.camera().position);
  for (const auto& [side, up, bgr] : {std::tuple<float, float, cv::Scalar>{-1, 1, top_left},
                                      {1, 1, top_right},
                                      {-1, -1, bottom_left},
                                      {1, -1, bottom_right}}) {
    const Eigen::Vector3f aim =
        b.origin + side * 0.25f * b.width * b.across + Eigen::Vector3f(0, 0, (0.5f + up * 0.25f) * b.height);
    float t, alpha;
    Rgb rad;
    ASSERT_TRUE(b.Intersect(cam, (aim - cam).normalized(), &t, &rad, &alpha));
    EXPECT_NEAR(alpha, 1.0f, 1e-6f);
    EXPECT_NEAR(ToSrgb8(Tone(rad[0])), bgr[2], 1) << side << " " << up;
    EXPECT_NEAR(ToSrgb8(Tone(rad[1])), bgr[1], 1) << side << " " << up;
    EXPECT_NEAR(ToSrgb8(Tone(rad[2])), bgr[0], 1) << side << " " << up;
  }
  std::filesystem::remove_all(dir);
}

TEST(Backdrop, MissingFilesAreNamed) {
  RenderParams p = TestParams();
  p.background_image = "/nonexistent/photo.jpg";
  try {
    Renderer r(p);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/photo.jpg"), std::string::npos);
  }
  EXPECT_THROW(ListBackgroundImages("/nonexistent/folder"), std::runtime_error);
  // A file given as the folder is said to be one (it was "does not exist").
  const std::string file = testing::TempDir() + "/render_bg_file_" + std::to_string(::getpid());
  std::ofstream(file) << "x";
  try {
    ListBackgroundImages(file);
    ADD_FAILURE() << "a file listed as a folder";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "background folder '" + file + "' is a file, expected a folder of images");
  }
  std::filesystem::remove(file);
}

// An image that cannot be read is named when the folder is listed: make-dataset found it only when
// a simulation drew it, after the simulation's work, and failed every simulation that drew it.
TEST(Backdrop, AFolderHoldingAnUnreadableImageIsRefusedNamingIt) {
  const std::string dir = testing::TempDir() + "/render_bg_bad_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  ASSERT_TRUE(cv::imwrite(dir + "/a.png", cv::Mat(8, 16, CV_8UC3, cv::Scalar(10, 20, 30))));
  // A PNG under 8 px is an image too (read at an eighth of its size it was 0 px, "unreadable").
  ASSERT_TRUE(cv::imwrite(dir + "/a4.png", cv::Mat(4, 4, CV_8UC3, cv::Scalar(10, 20, 30))));
  EXPECT_EQ(ListBackgroundImages(dir).size(), 2u);
  std::filesystem::remove(dir + "/a4.png");
  std::ofstream(dir + "/b.jpg") << "notanimage";
  try {
    ListBackgroundImages(dir);
    ADD_FAILURE() << "a folder with an unreadable b.jpg was listed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/b.jpg as an image"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(Backdrop, ProceduralHasGroundThingsBelowAndSkyAbove) {
  for (uint64_t seed = 0; seed < 5; ++seed) {
    const Texture t = ProceduralBackdrop(seed, 128, 64);
    float top = 0, bottom = 0;
    for (int x = 0; x < 128; ++x) {
      top += t.alpha(x, 0);
      bottom += t.alpha(x, 63);
    }
    EXPECT_EQ(top, 0.0f) << seed;        // 45 m up: sky
    EXPECT_EQ(bottom, 128.0f) << seed;   // at the ground: field
  }
}

}  // namespace
}  // namespace clothwind::render
