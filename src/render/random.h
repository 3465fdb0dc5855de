#ifndef CLOTHWIND_RENDER_RANDOM_H_
#define CLOTHWIND_RENDER_RANDOM_H_

#include <cstdint>
#include <initializer_list>

namespace clothwind::render {

// Seeded generator (SplitMix64) whose stream is fixed by the seed alone on every platform:
// render parameters, textures and pixel samples must be reproducible from a seed, and the
// <random> distributions are implementation-defined.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}

  uint64_t Next() {
    uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  // Uniform in [0, 1).
  double Uniform() { return static_cast<double>(Next() >> 11) * 0x1.0p-53; }
  // Uniform in [a, b).
  double Uniform(double a, double b) { return a + (b - a) * Uniform(); }
  // Uniform integer in [0, n); n > 0.
  int UniformInt(int n) { return static_cast<int>(Uniform() * n) % n; }
  // Uniform float in [0, 1) for per-pixel sampling.
  float UniformF() { return static_cast<float>(Next() >> 40) * 0x1.0p-24f; }

 private:
  uint64_t state_;
};

// Mixes several integers into one seed: pixel samples are drawn from Rng(HashSeed(seed, x, y,
// frame)) so an image does not depend on how rows are shared among threads.
inline uint64_t HashSeed(uint64_t a, uint64_t b = 0, uint64_t c = 0, uint64_t d = 0) {
  uint64_t h = a * 0x9e3779b97f4a7c15ULL;
  for (uint64_t x : {b, c, d}) {
    h ^= x + 0x632be59bd9b4e019ULL + (h << 6) + (h >> 2);
    h *= 0xbf58476d1ce4e5b9ULL;
    h ^= h >> 31;
  }
  return h;
}

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_RANDOM_H_
