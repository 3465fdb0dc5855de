#include "render/render_params.h"

#include <limits>
#include <string>

#include <gtest/gtest.h>

#include <set>

#include "render/test_meshes.h"

namespace clothwind::render {
namespace {

TEST(RenderParams, JsonRoundTripKeepsEveryField) {
  for (SceneKind kind : {SceneKind::kFlag, SceneKind::kCloth}) {
    const RenderParams p = SampleRenderParams(kind, 77, {"/data/a.jpg", "/data/b.jpg"});
    const nlohmann::json j = ToJson(p);
    // Through text, as label.json stores it.
    const RenderParams q = RenderParamsFromJson(nlohmann::json::parse(j.dump()));
    EXPECT_EQ(ToJson(q), j);
    EXPECT_EQ(q.seed, p.seed);
    EXPECT_EQ(q.texture_seed, p.texture_seed);  // 64-bit seeds survive exactly
    EXPECT_EQ(q.background_seed, p.background_seed);
    EXPECT_DOUBLE_EQ(q.sun_strength, p.sun_strength);
    EXPECT_EQ(q.background_image, p.background_image);
    EXPECT_EQ(q.scene, kind);
  }
  // Fields sampling leaves at their defaults, set to others: each must be read back, not
  // defaulted again (comparing the JSON of a default-valued field proves nothing).
  RenderParams p = SampleRenderParams(SceneKind::kFlag, 78);
  p.fps = 30;
  p.camera_fov_deg = 52.5;
  p.has_look_at = true;
  p.look_at[0] = 1.5, p.look_at[1] = -0.25, p.look_at[2] = 3.75;
  p.width = 320;
  p.height = 240;
  p.samples = 7;
  const RenderParams q = RenderParamsFromJson(nlohmann::json::parse(ToJson(p).dump()));
  EXPECT_EQ(q.fps, 30);
  EXPECT_EQ(q.camera_fov_deg, 52.5);
  EXPECT_TRUE(q.has_look_at);
  EXPECT_EQ(q.look_at[0], 1.5);
  EXPECT_EQ(q.look_at[1], -0.25);
  EXPECT_EQ(q.look_at[2], 3.75);
  EXPECT_EQ(q.width, 320);
  EXPECT_EQ(q.height, 240);
  EXPECT_EQ(q.samples, 7);
}

TEST(RenderParams, MissingOrMistypedFieldIsNamed) {
  nlohmann::json j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j.erase("sun_height");
  try {
    RenderParamsFromJson(j);
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sun_height"), std::string::npos) << e.what();
  }
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["samples"] = "four";
  EXPECT_THROW(RenderParamsFromJson(j), std::invalid_argument);
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["texture_name"] = "atlantis";
  EXPECT_THROW(RenderParamsFromJson(j), std::invalid_argument);
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["camera_radius"] = -1.0;
  EXPECT_THROW(RenderParamsFromJson(j), std::invalid_argument);
  // An integer beyond int's range, which get<int>() wrapped (4294967344 read as 48).
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["samples"] = 4294967300LL;
  try {
    RenderParamsFromJson(j);
    FAIL() << "a wrapped integer was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'samples' must be an integer, got 4294967300"), std::string::npos) << e.what();
  }
}

// Each bounded field alone out of range: the error names that field (a check of two fields named
// the first, with the larger value, whichever was wrong).
TEST(RenderParams, EachFieldOutOfRangeIsNamedAlone) {
  for (const char* field : {"sun_height", "sun_radius", "camera_height", "camera_radius", "mesh_height",
                            "mesh_width"}) {
    nlohmann::json j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
    j[field] = 20000.0;
    try {
      RenderParamsFromJson(j);
      ADD_FAILURE() << field << " 20000 was accepted";
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(std::string("field '") + field + "' is 20000"), std::string::npos) << field << ": " << what;
    }
  }
}

std::string FromJsonError(const nlohmann::json& j) {
  try {
    RenderParamsFromJson(j);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

// Lower bounds that name their field: a background_scale of 1e-50 became 0 as a float (NaN
// texture coordinates), a camera_radius of 1e-10 failed inside the camera as "viewing direction
// is vertical", and a camera 2 km up saw sky below the horizon.
TEST(RenderParams, TinyScaleAndRadiusAndHighCameraAreNamed) {
  nlohmann::json j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["background_scale"] = 1e-50;
  EXPECT_NE(FromJsonError(j).find("field 'background_scale' is"), std::string::npos) << FromJsonError(j);
  EXPECT_NE(FromJsonError(j).find(">= 0.01"), std::string::npos) << FromJsonError(j);
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["camera_radius"] = 1e-10;
  EXPECT_NE(FromJsonError(j).find("field 'camera_radius' is"), std::string::npos) << FromJsonError(j);
  EXPECT_NE(FromJsonError(j).find(">= 0.1 m"), std::string::npos) << FromJsonError(j);
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["camera_height"] = 2000.0;
  EXPECT_NE(FromJsonError(j).find("field 'camera_height' is 2000"), std::string::npos) << FromJsonError(j);
  // The bounds themselves are usable.
  j = ToJson(SampleRenderParams(SceneKind::kFlag, 1));
  j["background_scale"] = 0.01;
  j["camera_radius"] = kMinCameraRadius;
  j["camera_height"] = 1000.0;
  EXPECT_EQ(FromJsonError(j), "no error");
  CameraRanges r;
  r.radius_min = 1e-10;
  EXPECT_THROW(ValidateCameraRanges(r), std::invalid_argument);
}

// The cache limit is on width x height x samples; a frame too big by itself is named by its size
// (an 8192x8192 frame with 1 sample was refused as 'samples').
TEST(RenderParams, TooManyPixelSamplesNameTheRightField) {
  RenderParams p = SampleRenderParams(SceneKind::kFlag, 1);
  p.width = p.height = 8192;
  p.samples = 1;
  try {
    ValidateRenderParams(p);
    FAIL() << "8192x8192 was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("fields 'width' x 'height' are 8192 x 8192"), std::string::npos) << what;
    EXPECT_EQ(what.find("'samples'"), std::string::npos) << what;
  }
  p.width = p.height = 300;
  p.samples = 1024;
  try {
    ValidateRenderParams(p);
    FAIL() << "300x300 x 1024 samples was accepted";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("field 'samples' is 1024"), std::string::npos) << what;
    EXPECT_NE(what.find("expected at most 186 for a 300x300 frame"), std::string::npos) << what;
  }
  p.samples = 186;
  EXPECT_NO_THROW(ValidateRenderParams(p));
}

// The cloth's rest size from any frame of it, and the ζ fields that disagree with it named.
TEST(MeshSize, MeasuredFromTheTextureMapAndMismatchesNamed) {
  const ClothMesh flat = FlatCloth(7, 5, 3.0, 2.0);
  const Eigen::Vector2d s = MeasureClothSize(flat.V, flat.F, flat.UV);
  EXPECT_NEAR(s.x(), 3.0, 1e-12);
  EXPECT_NEAR(s.y(), 2.0, 1e-12);
  // Flying and folded, the material keeps its size (the test flag's waves stretch it ~3 %).
  const ClothMesh waving = WavingFlag(39, 26, 3.0, 2.0, 0.3);
  const Eigen::Vector2d w = MeasureClothSize(waving.V, waving.F, waving.UV);
  EXPECT_NEAR(w.x(), 3.0, 0.1);
  EXPECT_NEAR(w.y(), 2.0, 0.06);
  const RenderParams flag = SampleRenderParams(SceneKind::kFlag, 1);
  EXPECT_EQ(MeshSizeMismatch(flag, w), "");
  const ClothMesh cloth = HangingCloth(32, 32, 1.0, 1.0, 0.2);
  EXPECT_EQ(MeshSizeMismatch(SampleRenderParams(SceneKind::kCloth, 1),
                             MeasureClothSize(cloth.V, cloth.F, cloth.UV)),
            "");
  // A 6x4 m flag under a 3x2 m ζ: the pole and aim would be wrong.
  const std::string big = MeshSizeMismatch(flag, Eigen::Vector2d(6.0, 4.0));
  EXPECT_NE(big.find("field 'mesh_width' is 3 m but the cloth being rendered is 6 m"), std::string::npos) << big;
  const std::string square = MeshSizeMismatch(flag, Eigen::Vector2d(3.0, 3.0));
  EXPECT_NE(square.find("field 'mesh_aspect_ratio' is 1.5"), std::string::npos) << square;
  EXPECT_NE(square.find("3 m by 3 m"), std::string::npos) << square;
  EXPECT_EQ(MeshSizeMismatch(flag, Eigen::Vector2d(3.1, 1.94)), "");  // within 5 %
  // Texture coordinates without area cannot say.
  ClothMesh none = flat;
  none.UV.col(1).setZero();
  EXPECT_THROW(MeasureClothSize(none.V, none.F, none.UV), std::invalid_argument);
}

TEST(RenderParams, SamplesStayInTableTwoRanges) {
  for (uint64_t seed = 0; seed < 300; ++seed) {
    const RenderParams f = SampleRenderParams(SceneKind::kFlag, seed);
    EXPECT_GE(f.background_offset, -20); EXPECT_LE(f.background_offset, 20);
    EXPECT_GE(f.background_scale, 0.6); EXPECT_LE(f.background_scale, 1.0);
    EXPECT_GE(f.sun_height, 4); EXPECT_LE(f.sun_height, 10);
    EXPECT_GE(f.sun_radius, 0); EXPECT_LE(f.sun_radius, 5);
    EXPECT_GE(f.sun_strength, 2); EXPECT_LE(f.sun_strength, 10);
    EXPECT_GE(f.sun_shadow_soft_size, 2); EXPECT_LE(f.sun_shadow_soft_size, 10);
    EXPECT_GE(f.camera_height, 0.2); EXPECT_LE(f.camera_height, 3);
    EXPECT_GE(f.camera_radius, 4); EXPECT_LE(f.camera_radius, 6);
    EXPECT_GE(f.camera_angle_deg, -15); EXPECT_LE(f.camera_angle_deg, 15);
    EXPECT_DOUBLE_EQ(f.mesh_height, 4.6);
    EXPECT_DOUBLE_EQ(f.mesh_aspect_ratio, 1.5);
    EXPECT_EQ(f.texture_kind, "flag");
    EXPECT_NO_THROW(ValidateRenderParams(f));
    const RenderParams c = SampleRenderParams(SceneKind::kCloth, seed);
    EXPECT_GE(c.camera_height, 0.5); EXPECT_LE(c.camera_height, 2);
    EXPECT_GE(c.camera_radius, 1); EXPECT_LE(c.camera_radius, 2.5);
    EXPECT_GE(c.camera_angle_deg, -5); EXPECT_LE(c.camera_angle_deg, 5);
    EXPECT_DOUBLE_EQ(c.mesh_height, 2.0);
    EXPECT_DOUBLE_EQ(c.mesh_aspect_ratio, 1.0);
    EXPECT_EQ(c.texture_kind, "fabric");
    EXPECT_NO_THROW(ValidateRenderParams(c));
  }
}

TEST(RenderParams, CamerasComeFromTheGivenRangesAndNothingElseMoves) {
  CameraRanges level;  // a camera on a roof, level with the flag's centre (5.6 m)
  level.height_min = 5.1, level.height_max = 6.1;
  level.radius_min = 8, level.radius_max = 9;
  level.angle_max_deg = 3;
  for (uint64_t seed = 0; seed < 200; ++seed) {
    const RenderParams table = SampleRenderParams(SceneKind::kFlag, seed);
    EXPECT_EQ(ToJson(table), ToJson(SampleRenderParams(SceneKind::kFlag, seed, {},
                                                       TableTwoCameraRanges(SceneKind::kFlag))));
    RenderParams p = SampleRenderParams(SceneKind::kFlag, seed, {}, level);
    EXPECT_GE(p.camera_height, 5.1); EXPECT_LE(p.camera_height, 6.1);
    EXPECT_GE(p.camera_radius, 8); EXPECT_LE(p.camera_radius, 9);
    EXPECT_GE(p.camera_angle_deg, -3); EXPECT_LE(p.camera_angle_deg, 3);
    // The same place in the stream: the same fraction of each range.
    EXPECT_NEAR((p.camera_height - 5.1) / 1.0, (table.camera_height - 0.2) / 2.8, 1e-12);
    // Everything else (sun, backdrop, texture) is the Table 2 draw's.
    p.camera_height = table.camera_height;
    p.camera_radius = table.camera_radius;
    p.camera_angle_deg = table.camera_angle_deg;
    EXPECT_EQ(ToJson(p), ToJson(table));
  }
  const RenderParams c = SampleRenderParams(SceneKind::kCloth, 3, {}, TableTwoCameraRanges(SceneKind::kCloth));
  EXPECT_EQ(ToJson(c), ToJson(SampleRenderParams(SceneKind::kCloth, 3)));
}

TEST(RenderParams, BadCameraRangesNameTheRange) {
  const auto message = [](const CameraRanges& r) {
    try {
      ValidateCameraRanges(r);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  CameraRanges r;
  r.height_min = 3, r.height_max = 2;
  EXPECT_NE(message(r).find("camera height is [3, 2], expected 0 < min <= max"), std::string::npos) << message(r);
  r = CameraRanges();
  r.radius_min = 0;
  EXPECT_NE(message(r).find("camera radius"), std::string::npos) << message(r);
  r = CameraRanges();
  r.radius_max = std::numeric_limits<double>::infinity();  // passed max >= min; a header's null
  EXPECT_NE(message(r).find("camera radius is [") , std::string::npos) << message(r);
  EXPECT_NE(message(r).find("<= 1000 [m]"), std::string::npos) << message(r);
  r.radius_max = 1e308;  // finite, and every view failed as "viewing direction is vertical"
  EXPECT_NE(message(r).find("camera radius is ["), std::string::npos) << message(r);
  r = CameraRanges();
  r.angle_max_deg = 90;
  EXPECT_NE(message(r).find("camera angle"), std::string::npos) << message(r);
  EXPECT_EQ(message(CameraRanges()), "no error");
  EXPECT_THROW(SampleRenderParams(SceneKind::kFlag, 1, {}, r), std::invalid_argument);
}

TEST(RenderParams, SameSeedSameParamsOtherSeedOther) {
  EXPECT_EQ(ToJson(SampleRenderParams(SceneKind::kFlag, 5)),
            ToJson(SampleRenderParams(SceneKind::kFlag, 5)));
  EXPECT_NE(ToJson(SampleRenderParams(SceneKind::kFlag, 5)),
            ToJson(SampleRenderParams(SceneKind::kFlag, 6)));
}

TEST(RenderParams, AllFlagDesignsGetDrawn) {
  std::set<std::string> names;
  for (uint64_t seed = 0; seed < 400; ++seed)
    names.insert(SampleRenderParams(SceneKind::kFlag, seed).texture_name);
  EXPECT_GE(names.size(), 12u);
}

}  // namespace
}  // namespace clothwind::render
