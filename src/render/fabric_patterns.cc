#include "render/fabric_patterns.h"

#include <cmath>
#include <stdexcept>

#include "render/noise.h"
#include "common/random.h"

namespace clothwind::render {

namespace {
const char* const kNames[kNumFabricPatterns] = {"plain", "stripes", "checks", "dots", "knit"};

// A random dyed-fabric colour: hue anywhere, moderate saturation, any value.
Rgb RandomFabricColour(Rng& rng) {
  const float h = static_cast<float>(rng.Uniform()) * 6.0f;
  const float s = static_cast<float>(rng.Uniform(0.15, 0.85));
  const float val = static_cast<float>(rng.Uniform(0.15, 0.95));
  const int i = static_cast<int>(h) % 6;
  const float f = h - std::floor(h);
  const float p = val * (1 - s), q = val * (1 - s * f), t = val * (1 - s * (1 - f));
  float r = 0, g = 0, b = 0;
  switch (i) {
    case 0: r = val; g = t; b = p; break;
    case 1: r = q; g = val; b = p; break;
    case 2: r = p; g = val; b = t; break;
    case 3: r = p; g = q; b = val; break;
    case 4: r = t; g = p; b = val; break;
    default: r = val; g = p; b = q; break;
  }
  return Rgb(SrgbToLinear(r), SrgbToLinear(g), SrgbToLinear(b));
}

inline float Fract(float x) { return x - std::floor(x); }
}  // namespace

std::string FabricPatternName(FabricPattern pattern) {
  const int i = static_cast<int>(pattern);
  if (i < 0 || i >= kNumFabricPatterns) throw std::invalid_argument("FabricPatternName: bad pattern");
  return kNames[i];
}

FabricPattern FabricPatternFromName(const std::string& name) {
  for (int i = 0; i < kNumFabricPatterns; ++i)
    if (name == kNames[i]) return static_cast<FabricPattern>(i);
  throw std::invalid_argument("unknown fabric pattern '" + name +
                              "' (expected plain, stripes, checks, dots or knit)");
}

Texture DrawFabric(FabricPattern pattern, uint64_t seed, int size) {
  Rng rng(HashSeed(seed, 0xfab));
  const Rgb c0 = RandomFabricColour(rng), c1 = RandomFabricColour(rng),
            c2 = RandomFabricColour(rng);
  // Repeats across the cloth (the cloth is ~1 m, so 8..30 repeats is 3..12 cm).
  const float repeats = static_cast<float>(rng.Uniform(8, 30));
  const float angle = rng.Uniform() < 0.3 ? static_cast<float>(M_PI / 4) : 0.0f;
  const bool horizontal = rng.Uniform() < 0.5;
  const float duty = static_cast<float>(rng.Uniform(0.25, 0.6));
  const uint64_t nseed = rng.Next();
  Texture t(size, size);
  constexpr int kSs = 2;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      Rgb sum = Rgb::Zero();
      for (int sy = 0; sy < kSs; ++sy)
        for (int sx = 0; sx < kSs; ++sx) {
          const float u = (x + (sx + 0.5f) / kSs) / size;
          const float v = 1.0f - (y + (sy + 0.5f) / kSs) / size;
          float a = horizontal ? v : u, b = horizontal ? u : v;
          if (angle != 0.0f) {
            const float ca = std::cos(angle), sa = std::sin(angle);
            const float ra = ca * a + sa * b, rb = -sa * a + ca * b;
            a = ra;
            b = rb;
          }
          Rgb c = c0;
          switch (pattern) {
            case FabricPattern::kPlain:
              c = c0;
              break;
            case FabricPattern::kStripes: {
              const float f = Fract(a * repeats);
              c = f < duty ? c1 : (f < duty + 0.08f ? c2 : c0);
              break;
            }
            case FabricPattern::kChecks: {
              const bool sa = Fract(a * repeats) < 0.5f, sb = Fract(b * repeats) < 0.5f;
              c = (sa && sb) ? c1 : ((sa || sb) ? Rgb(0.5f * (c0 + c1)) : c0);
              break;
            }
            case FabricPattern::kDots: {
              const float gy = v * repeats;
              const float row = std::floor(gy);
              const float gx = u * repeats + 0.5f * (static_cast<int>(row) & 1);
              const float dx = Fract(gx) - 0.5f, dy = Fract(gy) - 0.5f;
              c = (dx * dx + dy * dy < 0.09f * duty) ? c1 : c0;
              break;
            }
            case FabricPattern::kKnit: {
              // Ribs: fine columns (V-shaped loops approximated by a chevron), heathered yarn.
              const float cols = repeats * 4.0f;
              const float loop = Fract(u * cols + 0.5f * std::abs(Fract(v * cols * 1.5f) - 0.5f));
              const float shade = 0.75f + 0.25f * std::sin(loop * 2.0f * static_cast<float>(M_PI));
              const float heather = FractalNoise(u * 60.0f, v * 60.0f, nseed, 3);
              c = (shade * (0.8f + 0.4f * heather)) * c0;
              break;
            }
            case FabricPattern::kCount:
              c = c0;
              break;
          }
          sum += c;
        }
      // A faint weave so even plain cloth shows some texture.
      const float weave = 0.94f + 0.12f * ValueNoise(x * 0.7f, y * 0.7f, nseed + 1);
      t.at(x, y) = (sum / (kSs * kSs)) * weave;
    }
  return t;
}

}  // namespace clothwind::render
