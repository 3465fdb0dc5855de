#include "render/noise.h"

#include <cmath>

#include "common/random.h"

namespace clothwind::render {

namespace {
inline float LatticeValue(int64_t x, int64_t y, uint64_t seed) {
  const uint64_t h = HashSeed(seed, static_cast<uint64_t>(x), static_cast<uint64_t>(y));
  return static_cast<float>(h >> 40) * 0x1.0p-24f;
}
inline float Smooth(float t) { return t * t * (3.0f - 2.0f * t); }
}  // namespace

float ValueNoise(float x, float y, uint64_t seed) {
  const float fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  const float tx = Smooth(x - fx), ty = Smooth(y - fy);
  const float a = LatticeValue(ix, iy, seed), b = LatticeValue(ix + 1, iy, seed);
  const float c = LatticeValue(ix, iy + 1, seed), d = LatticeValue(ix + 1, iy + 1, seed);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

float FractalNoise(float x, float y, uint64_t seed, int octaves) {
  float sum = 0.0f, amplitude = 1.0f, norm = 0.0f;
  for (int o = 0; o < octaves; ++o) {
    sum += amplitude * ValueNoise(x, y, seed + 7919u * o);
    norm += amplitude;
    amplitude *= 0.5f;
    x *= 2.0f;
    y *= 2.0f;
  }
  return norm > 0 ? sum / norm : 0.0f;
}

}  // namespace clothwind::render
