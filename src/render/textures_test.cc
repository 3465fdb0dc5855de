#include <gtest/gtest.h>

#include <limits>

#include "render/fabric_patterns.h"
#include "render/flag_designs.h"
#include "render/texture.h"

namespace clothwind::render {
namespace {

double MeanAbsDiff(const Texture& a, const Texture& b) {
  double s = 0;
  for (int y = 0; y < a.height(); ++y)
    for (int x = 0; x < a.width(); ++x) s += (a.at(x, y) - b.at(x, y)).cwiseAbs().sum();
  return s / (3.0 * a.width() * a.height());
}

TEST(FlagTexture, TricolourHasKnownColourAtKnownUv) {
  const FlagColours col = SampleFlagColours(3);
  const Texture t = DrawFlag(FlagDesign::kVerticalTricolour, col, 300, 200);
  // Band centres: hoist band c[1], middle c[0], fly band c[2].
  EXPECT_LT((t.Sample(1.0f / 6, 0.5f) - col.c[1]).norm(), 1e-5f);
  EXPECT_LT((t.Sample(0.5f, 0.5f) - col.c[0]).norm(), 1e-5f);
  EXPECT_LT((t.Sample(5.0f / 6, 0.9f) - col.c[2]).norm(), 1e-5f);
  // Exactly on the first band edge the bilinear lookup is the mean of the two bands.
  EXPECT_LT((t.Sample(100.0f / 300, 0.5f) - 0.5f * (col.c[1] + col.c[0])).norm(), 1e-5f);
  // A quarter texel either side: 3:1 blends.
  EXPECT_LT((t.Sample(99.75f / 300, 0.5f) - (0.75f * col.c[1] + 0.25f * col.c[0])).norm(), 1e-5f);
  const Texture h = DrawFlag(FlagDesign::kHorizontalTricolour, col, 300, 200);
  EXPECT_LT((h.Sample(0.5f, 5.0f / 6) - col.c[1]).norm(), 1e-5f);  // top band
  EXPECT_LT((h.Sample(0.5f, 1.0f / 6) - col.c[2]).norm(), 1e-5f);  // bottom band
}

TEST(FlagTexture, ColoursAreDistinctAndFollowTheSeed) {
  for (uint64_t seed = 0; seed < 50; ++seed) {
    const FlagColours a = SampleFlagColours(seed), b = SampleFlagColours(seed);
    for (int i = 0; i < 4; ++i) {
      EXPECT_EQ(a.c[i], b.c[i]);
      for (int j = 0; j < i; ++j) EXPECT_GT((a.c[i] - a.c[j]).norm(), 0.02f) << seed;
    }
  }
  EXPECT_NE(SampleFlagColours(1).c[0], SampleFlagColours(2).c[0]);
}

TEST(FlagTexture, AtLeastTwelveDistinctDesigns) {
  const FlagColours col = SampleFlagColours(11);
  std::vector<Texture> t;
  for (int d = 0; d < kNumFlagDesigns; ++d) t.push_back(DrawFlag(static_cast<FlagDesign>(d), col, 90, 60));
  ASSERT_GE(kNumFlagDesigns, 12);
  for (int i = 0; i < kNumFlagDesigns; ++i)
    for (int j = 0; j < i; ++j)
      EXPECT_GT(MeanAbsDiff(t[i], t[j]), 0.01)
          << FlagDesignName(static_cast<FlagDesign>(i)) << " vs "
          << FlagDesignName(static_cast<FlagDesign>(j));
}

TEST(FlagTexture, NamesRoundTrip) {
  for (int d = 0; d < kNumFlagDesigns; ++d)
    EXPECT_EQ(static_cast<int>(FlagDesignFromName(FlagDesignName(static_cast<FlagDesign>(d)))), d);
  EXPECT_THROW(FlagDesignFromName("nowhere"), std::invalid_argument);
}

TEST(FabricTexture, PatternsDifferAndFollowTheSeed) {
  for (int p = 0; p < kNumFabricPatterns; ++p) {
    const FabricPattern pat = static_cast<FabricPattern>(p);
    EXPECT_EQ(MeanAbsDiff(DrawFabric(pat, 4, 64), DrawFabric(pat, 4, 64)), 0.0);
    EXPECT_GT(MeanAbsDiff(DrawFabric(pat, 4, 64), DrawFabric(pat, 5, 64)), 0.005);
    EXPECT_EQ(static_cast<int>(FabricPatternFromName(FabricPatternName(pat))), p);
  }
  // Same colours (same seed), different layouts.
  const Texture plain = DrawFabric(FabricPattern::kPlain, 9, 64);
  for (int p = 1; p < kNumFabricPatterns; ++p)
    EXPECT_GT(MeanAbsDiff(plain, DrawFabric(static_cast<FabricPattern>(p), 9, 64)), 0.005) << p;
}

TEST(Texture, WrapModes) {
  Texture t(2, 1);
  t.at(0, 0) = Rgb(1, 0, 0);
  t.at(1, 0) = Rgb(0, 0, 1);
  EXPECT_LT((t.Sample(-3.0f, 0.5f, Wrap::kClamp) - Rgb(1, 0, 0)).norm(), 1e-6f);
  EXPECT_LT((t.Sample(1.25f, 0.5f, Wrap::kRepeat) - Rgb(1, 0, 0)).norm(), 1e-6f);
  EXPECT_LT((t.Sample(1.25f, 0.5f, Wrap::kMirror) - Rgb(0, 0, 1)).norm(), 1e-6f);
}

// Coordinates past int's range: the float-to-int conversion was undefined (x86: INT_MIN), so
// u = 1e30 read the left edge under kClamp, and NaN gave NaN colours.
TEST(Texture, HugeInfiniteAndNanCoordinates) {
  Texture t(2, 1);
  t.at(0, 0) = Rgb(1, 0, 0);
  t.at(1, 0) = Rgb(0, 0, 1);
  const float inf = std::numeric_limits<float>::infinity();
  for (float u : {1e30f, 3e9f, inf})
    EXPECT_LT((t.Sample(u, 0.5f, Wrap::kClamp) - Rgb(0, 0, 1)).norm(), 1e-6f) << u;
  for (float u : {-1e30f, -3e9f, -inf})
    EXPECT_LT((t.Sample(u, 0.5f, Wrap::kClamp) - Rgb(1, 0, 0)).norm(), 1e-6f) << u;
  for (Wrap w : {Wrap::kRepeat, Wrap::kMirror})
    for (float u : {1e30f, -1e30f, inf, -inf}) {
      float alpha = -1;
      const Rgb c = t.Sample(u, 1e30f, w, &alpha);
      EXPECT_TRUE(c.allFinite()) << u;
      EXPECT_EQ(alpha, 1.0f) << u;
    }
  float alpha = -1;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_EQ(t.Sample(nan, 0.5f, Wrap::kRepeat, &alpha), Rgb::Zero());
  EXPECT_EQ(alpha, 0.0f);
  EXPECT_EQ(t.Sample(0.5f, nan), Rgb::Zero());
}

}  // namespace
}  // namespace clothwind::render
