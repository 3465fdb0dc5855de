#ifndef CLOTHWIND_SIM_RANDOM_H_
#define CLOTHWIND_SIM_RANDOM_H_

#include <cmath>
#include <cstdint>

namespace clothwind::sim {

// A small seeded generator (SplitMix64) whose output is fixed by the seed alone, on every
// platform and standard library: the wind fields must be reproducible from a seed, and the
// <random> distributions are implementation-defined.
class SplitMix64 {
 public:
  explicit SplitMix64(uint64_t seed) : state_(seed) {}

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

 private:
  uint64_t state_;
};

// Derives an independent seed for a sub-stream (e.g. gusts vs turbulence from one --seed).
inline uint64_t DeriveSeed(uint64_t seed, uint64_t stream) {
  SplitMix64 g(seed ^ (0xd1b54a32d192ed03ULL * (stream + 1)));
  return g.Next();
}

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_RANDOM_H_
