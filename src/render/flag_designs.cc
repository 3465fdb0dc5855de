#include "render/flag_designs.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/random.h"

namespace clothwind::render {

namespace {

const char* const kNames[kNumFlagDesigns] = {
    "vertical_tricolour", "horizontal_tricolour", "horizontal_bicolour", "nordic_cross",
    "stripes_with_canton", "disc_on_field", "diagonal_bicolour", "diagonal_band", "saltire",
    "centred_cross", "hoist_triangle", "hoist_band", "star_on_field", "crescent_and_star",
    "five_bands", "quartered"};

// Common flag colours (sRGB 8-bit). Entry 0 is white, entries 1.. are saturated or dark, so a
// design gets contrast by pairing white with the others most of the time.
const int kPalette[][3] = {
    {245, 245, 245},  // white
    {200, 16, 46},    // red
    {0, 56, 147},     // blue
    {0, 36, 100},     // navy
    {90, 160, 220},   // sky blue
    {0, 122, 61},     // green
    {252, 209, 22},   // yellow
    {255, 130, 0},    // orange
    {25, 25, 25},     // black
    {128, 20, 40},    // maroon
};
constexpr int kPaletteSize = sizeof(kPalette) / sizeof(kPalette[0]);

bool InPolygon(float x, float y, const float (*p)[2], int n) {
  bool inside = false;
  for (int i = 0, j = n - 1; i < n; j = i++) {
    if (((p[i][1] > y) != (p[j][1] > y)) &&
        (x < (p[j][0] - p[i][0]) * (y - p[i][1]) / (p[j][1] - p[i][1]) + p[i][0]))
      inside = !inside;
  }
  return inside;
}

// Five-pointed star, one point up, centre (cx, cy), outer radius r (same units for x and y).
bool InStar(float x, float y, float cx, float cy, float r, float rotation = 0.0f) {
  float p[10][2];
  const float inner = r * 0.382f;
  for (int k = 0; k < 10; ++k) {
    const float a = static_cast<float>(M_PI) / 2 + rotation + k * static_cast<float>(M_PI) / 5;
    const float rr = (k % 2 == 0) ? r : inner;
    p[k][0] = cx + rr * std::cos(a);
    p[k][1] = cy + rr * std::sin(a);
  }
  return InPolygon(x, y, p, 10);
}

inline bool InDisc(float x, float y, float cx, float cy, float r) {
  return (x - cx) * (x - cx) + (y - cy) * (y - cy) <= r * r;
}

}  // namespace

std::string FlagDesignName(FlagDesign design) {
  const int i = static_cast<int>(design);
  if (i < 0 || i >= kNumFlagDesigns) throw std::invalid_argument("FlagDesignName: bad design");
  return kNames[i];
}

FlagDesign FlagDesignFromName(const std::string& name) {
  for (int i = 0; i < kNumFlagDesigns; ++i)
    if (name == kNames[i]) return static_cast<FlagDesign>(i);
  throw std::invalid_argument("unknown flag design '" + name +
                              "' (expected e.g. vertical_tricolour, nordic_cross, saltire)");
}

FlagColours SampleFlagColours(uint64_t seed) {
  Rng rng(HashSeed(seed, 0xf1a6));
  int order[kPaletteSize];
  for (int i = 0; i < kPaletteSize; ++i) order[i] = i;
  for (int i = kPaletteSize - 1; i > 0; --i) std::swap(order[i], order[rng.UniformInt(i + 1)]);
  // White appears in most real flags: put it among the first three colours 60% of the time.
  if (rng.Uniform() < 0.6) {
    int* w = std::find(order, order + kPaletteSize, 0);
    if (w - order >= 3) std::swap(*w, order[rng.UniformInt(3)]);
  }
  FlagColours out;
  for (int k = 0; k < 4; ++k) {
    const int* s = kPalette[order[k]];
    Rgb c = FromSrgb8(s[0], s[1], s[2]);
    const float gain = static_cast<float>(rng.Uniform(0.85, 1.1));
    const Rgb tint(static_cast<float>(rng.Uniform(0.94, 1.06)), 1.0f,
                   static_cast<float>(rng.Uniform(0.94, 1.06)));
    out.c[k] = (c.cwiseProduct(tint) * gain).cwiseMin(0.92f).cwiseMax(0.004f);
  }
  return out;
}

Rgb FlagColourAt(FlagDesign design, const FlagColours& colours, float u, float v,
                 float aspect) {
  const Rgb& a = colours.c[0];
  const Rgb& b = colours.c[1];
  const Rgb& c = colours.c[2];
  const Rgb& d = colours.c[3];
  // x, y in units of the flag's height, so circles and stars stay round.
  const float x = u * aspect, y = v;
  switch (design) {
    case FlagDesign::kVerticalTricolour:
      return u < 1.0f / 3 ? b : (u < 2.0f / 3 ? a : c);
    case FlagDesign::kHorizontalTricolour:
      return v > 2.0f / 3 ? b : (v > 1.0f / 3 ? a : c);
    case FlagDesign::kHorizontalBicolour:
      return v > 0.5f ? a : b;
    case FlagDesign::kNordicCross: {
      const float cx = 0.375f * aspect, half = 0.1f, fim = 0.05f;
      const float dx = std::abs(x - cx), dy = std::abs(y - 0.5f);
      if (dx < half || dy < half) return c;
      if (dx < half + fim || dy < half + fim) return a;
      return b;
    }
    case FlagDesign::kStripesWithCanton: {
      const int stripes = 9;
      const int s = std::min(stripes - 1, static_cast<int>((1.0f - v) * stripes));
      if (u < 0.4f && v > 1.0f - 5.0f / stripes) {
        // Canton with a 5x4 grid of small stars.
        const float cu = u / 0.4f, cv = (v - (1.0f - 5.0f / stripes)) / (5.0f / stripes);
        const float gx = cu * 6.0f, gy = cv * 5.0f;
        const float fx = gx - std::floor(gx), fy = gy - std::floor(gy);
        const bool inside = gx >= 0.5f && gx < 5.5f && gy >= 0.5f && gy < 4.5f;
        if (inside && InStar(fx, fy, 0.5f, 0.5f, 0.38f)) return a;
        return c;
      }
      return s % 2 == 0 ? b : a;
    }
    case FlagDesign::kDiscOnField:
      return InDisc(x, y, 0.45f * aspect, 0.5f, 0.3f) ? b : (a == b ? c : a);
    case FlagDesign::kDiagonalBicolour:
      return (y < u) ? b : c;
    case FlagDesign::kDiagonalBand: {
      // Signed distance to the diagonal from (0,0) to (aspect,1), in height units.
      const float n = std::sqrt(aspect * aspect + 1.0f);
      const float dist = (x * 1.0f - y * aspect) / n;
      if (std::abs(dist) < 0.12f) return d;
      if (std::abs(dist) < 0.17f) return c;
      return dist > 0 ? b : a;
    }
    case FlagDesign::kSaltire: {
      const float n = std::sqrt(aspect * aspect + 1.0f);
      const float d1 = std::abs(x - y * aspect) / n;
      const float d2 = std::abs(x - (1.0f - y) * aspect) / n;
      return (d1 < 0.1f || d2 < 0.1f) ? a : b;
    }
    case FlagDesign::kCentredCross: {
      const float dx = std::abs(x - 0.5f * aspect), dy = std::abs(y - 0.5f);
      return (dx < 0.1f || dy < 0.1f) ? b : a;
    }
    case FlagDesign::kHoistTriangle: {
      // Triangle from the hoist to the centre point (0.5 of the length... reaching x = 0.6).
      const float reach = 0.6f;
      if (x < reach * (1.0f - std::abs(y - 0.5f) * 2.0f)) return c;
      return v > 0.5f ? a : b;
    }
    case FlagDesign::kHoistBand:
      if (u < 0.25f) return b;
      return v > 2.0f / 3 ? c : (v > 1.0f / 3 ? a : d);
    case FlagDesign::kStarOnField:
      return InStar(x, y, 0.5f * aspect, 0.5f, 0.32f) ? c : b;
    case FlagDesign::kCrescentAndStar: {
      const float cx = 0.38f * aspect;
      const bool crescent = InDisc(x, y, cx, 0.5f, 0.25f) && !InDisc(x, y, cx + 0.065f, 0.5f, 0.2f);
      const bool star = InStar(x, y, cx + 0.33f, 0.5f, 0.1f, -0.3f);
      return (crescent || star) ? a : b;
    }
    case FlagDesign::kFiveBands: {
      const float t = std::abs(v - 0.5f);
      return t < 1.0f / 6 ? c : (t < 1.0f / 3 ? a : b);
    }
    case FlagDesign::kQuartered: {
      const bool left = u < 0.5f, top = v > 0.5f;
      if (left == top) return a;
      return top ? b : c;
    }
    case FlagDesign::kCount:
      break;
  }
  return a;
}

Texture DrawFlag(FlagDesign design, const FlagColours& colours, int width, int height) {
  Texture t(width, height);
  const float aspect = static_cast<float>(width) / height;
  constexpr int kSs = 3;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      Rgb sum = Rgb::Zero();
      for (int sy = 0; sy < kSs; ++sy)
        for (int sx = 0; sx < kSs; ++sx) {
          const float u = (x + (sx + 0.5f) / kSs) / width;
          const float v = 1.0f - (y + (sy + 0.5f) / kSs) / height;
          sum += FlagColourAt(design, colours, u, v, aspect);
        }
      t.at(x, y) = sum / (kSs * kSs);
    }
  return t;
}

}  // namespace clothwind::render
