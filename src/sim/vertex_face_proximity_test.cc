// Vertex-face proximity: finds what it should, and stays fast on exploded (huge or NaN) states,
// which before the guard made the per-face cell loop practically endless.
#include <chrono>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>
#include <algorithm>

#include <gtest/gtest.h>

#include "sim/test_grid_faces.h"
#include "sim/vertex_face_proximity.h"

namespace clothwind::sim {
namespace {

// Two triangles (0,1,2), (3,4,5) 0.1 m wide and a loose vertex 6.
struct Fixture {
  Eigen::MatrixX3i F{2, 3};
  Eigen::MatrixX3d X{7, 3};
  Fixture() {
    F << 0, 1, 2, 3, 4, 5;
    X << 0, 0, 0, 0.1, 0, 0, 0, 0.1, 0,    // face 0 in z = 0
        1, 0, 0, 1.1, 0, 0, 1, 0.1, 0,     // face 1 in z = 0, 1 m away
        0.02, 0.02, 0.004;                 // 4 mm above face 0
  }
};

TEST(VertexFaceProximity, FindsVertexWithinThicknessAboveFace) {
  Fixture s;
  VertexFaceProximity prox(s.F, 7, 0.05);
  prox.Update(s.X, 0.01);
  ASSERT_EQ(prox.pairs().size(), 1u);
  EXPECT_EQ(prox.pairs()[0].vertex, 6);
  EXPECT_EQ(prox.pairs()[0].face, 0);
  EXPECT_EQ(prox.pairs()[0].side, 1.0);
  s.X(6, 2) = -0.004;
  prox.Update(s.X, 0.01);
  ASSERT_EQ(prox.pairs().size(), 1u);
  EXPECT_EQ(prox.pairs()[0].side, -1.0);
  s.X(6, 2) = 0.02;  // beyond the thickness
  prox.Update(s.X, 0.01);
  EXPECT_TRUE(prox.pairs().empty());
}

TEST(VertexFaceProximity, HugeAndNonFiniteFacesReturnPromptlyAndSparedFacesStillWork) {
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  for (double bad : {1e4, 1e9, 1e300, inf, -inf, nan}) {
    SCOPED_TRACE("bad coordinate " + std::to_string(bad));
    Fixture s;
    s.X(4, 0) = bad;  // face 1 spans from x = 1 to `bad` (or is non-finite)
    s.X(5, 2) = -bad;
    VertexFaceProximity prox(s.F, 7, 0.05);
    const auto t0 = std::chrono::steady_clock::now();
    prox.Update(s.X, 0.01);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // A 1e4 m face alone is (2e5 cells)^2 per axis pair: hours without the guard.
    EXPECT_LT(seconds, 0.5);
    // Face 0 and vertex 6 are untouched: their pair is still found.
    ASSERT_EQ(prox.pairs().size(), 1u);
    EXPECT_EQ(prox.pairs()[0].vertex, 6);
    EXPECT_EQ(prox.pairs()[0].face, 0);
  }
}

TEST(VertexFaceProximity, NonFiniteVertexIsIgnored) {
  Fixture s;
  s.X(6, 0) = std::numeric_limits<double>::quiet_NaN();
  VertexFaceProximity prox(s.F, 7, 0.05);
  prox.Update(s.X, 0.01);
  EXPECT_TRUE(prox.pairs().empty());
}

TEST(VertexFaceProximity, FromCandidatesEqualsUpdateGivenAllPairsAndOnlyLooksAmongThem) {
  // A sheet of 6 x 6 vertices folded over itself (layers ~8 mm apart): pairs within the thickness.
  const int n = 6;
  const Eigen::MatrixX3i F = GridFaces(n);
  Eigen::MatrixX3d X(n * n, 3);
  for (int i = 0; i < n * n; ++i)
    X.row(i) << (i / n >= n / 2 ? 0.05 * (n - 1 - i / n) + 0.01 : 0.05 * (i / n)) + 0.01 * std::sin(7.0 * i),
        0.05 * (i % n) + 0.01 * std::cos(5.0 * i), (i / n >= n / 2 ? 0.008 : 0.0) + 0.002 * std::sin(3.0 * i);
  const double thickness = 0.02;
  VertexFaceProximity full(F, n * n, 0.05), filtered(F, n * n, 0.05);
  full.Update(X, thickness);
  ASSERT_GE(full.pairs().size(), 3u) << "the test needs pairs";
  std::vector<std::pair<int, int>> all;  // every (vertex, face), in an order unlike Update's
  for (int v = n * n - 1; v >= 0; --v)
    for (int f = 0; f < F.rows(); ++f) all.emplace_back(v, f);
  filtered.UpdateFromCandidates(X, thickness, all);
  ASSERT_EQ(filtered.pairs().size(), full.pairs().size());
  for (size_t i = 0; i < full.pairs().size(); ++i) {
    EXPECT_EQ(filtered.pairs()[i].vertex, full.pairs()[i].vertex);
    EXPECT_EQ(filtered.pairs()[i].face, full.pairs()[i].face);
    EXPECT_EQ(filtered.pairs()[i].side, full.pairs()[i].side);
  }
  // Without the first pair among the candidates, that pair is not reported.
  const auto first = std::make_pair(full.pairs()[0].vertex, full.pairs()[0].face);
  all.erase(std::find(all.begin(), all.end(), first));
  filtered.UpdateFromCandidates(X, thickness, all);
  EXPECT_EQ(filtered.pairs().size(), full.pairs().size() - 1);
}

}  // namespace
}  // namespace clothwind::sim
