#ifndef CLOTHWIND_COMMON_RANDOM_H_
#define CLOTHWIND_COMMON_RANDOM_H_

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>

namespace clothwind {

// Seeded generator (SplitMix64, Steele, Lea and Flood 2014) whose stream is fixed by the seed
// alone on every platform and standard library: wind fields, render parameters, textures, pixel
// samples and dataset splits must be reproducible from a seed, and the <random> distributions are
// implementation-defined. The simulator and the renderer share this one generator, so a dataset
// made today equals one made from the same seeds a year ago.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}

  // The next 64 random bits.
  uint64_t Next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1), from the top 53 bits.
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  // Uniform in [a, b).
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }
  // Uniform integer in [0, n); n > 0.
  int UniformInt(int n) { return static_cast<int>(Uniform() * n) % n; }
  // Standard normal (Box-Muller from two uniforms, the first kept above 0 so the log is finite);
  // the same on every platform up to libm's last bits, unlike std::normal_distribution.
  double Normal() {
    const double u1 = std::max(Uniform(), 1e-300), u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  // Uniform float in [0, 1) from the top 24 bits, for per-pixel sampling.
  float UniformF() { return static_cast<float>(Next() >> 40) * 0x1.0p-24f; }

 private:
  uint64_t state_;
};

// Mixes up to four integers into one seed: the renderer draws a pixel's samples from
// Rng(HashSeed(seed, x, y)) (render/renderer.cc, PixelSampleAt: the same pattern every frame, so
// a still cloth renders the same) so an image does not depend on how rows are shared among
// threads.
inline uint64_t HashSeed(uint64_t a, uint64_t b = 0, uint64_t c = 0, uint64_t d = 0) {
  uint64_t h = a * 0x9e3779b97f4a7c15ULL;
  for (uint64_t x : {b, c, d}) {
    h ^= x + 0x632be59bd9b4e019ULL + (h << 6) + (h >> 2);
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 31;
  }
  return h;
}

// Derives the seed of sub-stream `stream` (e.g. gusts and turbulence from one --seed).
inline uint64_t DeriveSeed(uint64_t seed, uint64_t stream) {
  Rng g(seed ^ (0xd1b54a32d192ed03ULL * (stream + 1)));
  return g.Next();
}

}  // namespace clothwind

#endif  // CLOTHWIND_COMMON_RANDOM_H_
