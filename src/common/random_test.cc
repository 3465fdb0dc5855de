#include "common/random.h"

#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace clothwind {
namespace {

// The first outputs of the reference SplitMix64 (Vigna's splitmix64.c) for seed 1234567. Every
// FlagSim dataset is a function of this stream, so a change here would silently change them all.
TEST(RngTest, MatchesTheReferenceSplitMix64Stream) {
  Rng g(1234567);
  const std::vector<uint64_t> expected = {6457827717110365317ULL, 3203168211198807973ULL,
                                          9817491932198370423ULL, 4593380528125082431ULL,
                                          16408922859458223821ULL};
  for (uint64_t e : expected) EXPECT_EQ(g.Next(), e);
}

TEST(RngTest, UniformStaysInRangeWithTheRightMeanAndVariance) {
  Rng g(7);
  const int n = 200000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double u = g.Uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  const double mean = sum / n, var = sum2 / n - mean * mean;
  // Standard error of the mean is sqrt(1/12 / n) = 6.5e-4; allow five of them.
  EXPECT_NEAR(mean, 0.5, 5 * std::sqrt(1.0 / 12 / n));
  EXPECT_NEAR(var, 1.0 / 12, 2e-3);
}

// Moments of the normal draws: mean 0, variance 1, kurtosis 3 (a uniform or a triangular
// mistake would keep the first two and miss the third), and two draws use two uniforms.
TEST(RngTest, NormalDrawsHaveTheStandardNormalsMoments) {
  Rng g(5);
  const int n = 200000;
  double m1 = 0, m2 = 0, m4 = 0;
  for (int i = 0; i < n; ++i) {
    const double x = g.Normal();
    ASSERT_TRUE(std::isfinite(x));
    m1 += x;
    m2 += x * x;
    m4 += x * x * x * x;
  }
  m1 /= n;
  m2 /= n;
  m4 /= n;
  EXPECT_NEAR(m1, 0.0, 5 / std::sqrt(n));
  EXPECT_NEAR(m2, 1.0, 5 * std::sqrt(2.0 / n));
  EXPECT_NEAR(m4 / (m2 * m2), 3.0, 0.1);  // standard error of the kurtosis ~ sqrt(24 / n) = 0.011
  Rng a(9), b(9);
  a.Normal();
  b.Next();
  b.Next();
  EXPECT_EQ(a.Next(), b.Next());
  // The draws themselves, computed apart from this code (Python's SplitMix64 and Box-Muller):
  // cos for sin, or the two uniforms' roles swapped, kept every moment above and changed every
  // session's wind and every toy clip's noise without a word. Up to libm's last bits.
  Rng c(7);
  for (const double expected : {1.3649922974572284, -0.396523975253818, 0.004498526159832092, -0.5806130552620291})
    EXPECT_NEAR(c.Normal(), expected, 1e-14);
}

TEST(RngTest, ScaledUniformIntegerAndFloatDrawsStayInRange) {
  Rng g(11);
  std::set<int> seen;
  for (int i = 0; i < 10000; ++i) {
    const double x = g.Uniform(-2.0, 3.0);
    ASSERT_GE(x, -2.0);
    ASSERT_LT(x, 3.0);
    const int k = g.UniformInt(7);
    ASSERT_GE(k, 0);
    ASSERT_LT(k, 7);
    seen.insert(k);
    const float f = g.UniformF();
    ASSERT_GE(f, 0.0f);
    ASSERT_LT(f, 1.0f);
  }
  EXPECT_EQ(seen.size(), 7u);  // every value of [0, 7) is drawn
}

TEST(RngTest, SameSeedSameStreamDifferentSeedDifferentStream) {
  Rng a(99), b(99), c(100);
  for (int i = 0; i < 100; ++i) {
    const uint64_t x = a.Next();
    EXPECT_EQ(x, b.Next());
    EXPECT_NE(x, c.Next());
  }
}

// Values of an independent big-integer implementation of the same mixing (Python, arbitrary
// precision reduced mod 2^64): pixel and parameter seeds of every dataset come from these.
TEST(HashSeedTest, MatchesAnIndependentImplementation) {
  EXPECT_EQ(HashSeed(1, 2, 3, 4), 13331994088792984919ULL);
  EXPECT_EQ(HashSeed(7), 1448982422872344781ULL);
  EXPECT_EQ(DeriveSeed(42, 0), 14473931205035997723ULL);
  EXPECT_EQ(DeriveSeed(42, 1), 18048596636615606144ULL);
}

TEST(HashSeedTest, EveryArgumentAndItsPositionMatter) {
  const uint64_t base = HashSeed(5, 6, 7, 8);
  EXPECT_NE(base, HashSeed(4, 6, 7, 8));
  EXPECT_NE(base, HashSeed(5, 5, 7, 8));
  EXPECT_NE(base, HashSeed(5, 6, 6, 8));
  EXPECT_NE(base, HashSeed(5, 6, 7, 9));
  EXPECT_NE(HashSeed(1, 2), HashSeed(2, 1));
  // Neighbouring pixels get unrelated streams: no two of a 64 x 64 block share a seed.
  std::set<uint64_t> seeds;
  for (uint64_t x = 0; x < 64; ++x)
    for (uint64_t y = 0; y < 64; ++y) seeds.insert(HashSeed(3, x, y, 0));
  EXPECT_EQ(seeds.size(), 64u * 64u);
}

}  // namespace
}  // namespace clothwind
