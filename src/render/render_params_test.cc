#include "render/render_params.h"

#include <gtest/gtest.h>

#include <set>

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
