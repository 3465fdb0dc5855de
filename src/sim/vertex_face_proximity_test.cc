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

// A vertex within the thickness of a face's plane and inside its box grown by the thickness, but
// whose projection falls outside the triangle, is no pair (the other tests' vertices all project
// inside, so dropping the barycentric test passed them). One vertex beyond each edge: the
// hypotenuse (wb + wc > 1), the edge on the x axis (wc < 0) and the one on the y axis (wb < 0);
// the same vertex just inside the hypotenuse is found. Update and UpdateFromCandidates alike.
TEST(VertexFaceProximity, VertexBesideTheTriangleIsNoPair) {
  struct Case {
    double x, y;
    bool inside;
  };
  const Case cases[] = {{0.07, 0.07, false},   // beyond the hypotenuse (wb + wc = 1.4)
                        {0.052, 0.052, false}, // just beyond it (1.04)
                        {0.05, -0.005, false}, // below the edge along x
                        {-0.005, 0.05, false}, // left of the edge along y
                        {0.045, 0.045, true}}; // just inside the hypotenuse (0.9)
  for (const Case& c : cases) {
    SCOPED_TRACE("vertex at (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", 0.004)");
    Fixture s;
    s.X.row(6) << c.x, c.y, 0.004;  // 4 mm from the plane of face 0, within its grown box
    VertexFaceProximity prox(s.F, 7, 0.05), from_candidates(s.F, 7, 0.05);
    prox.Update(s.X, 0.01);
    std::vector<std::pair<int, int>> all;
    for (int v = 0; v < 7; ++v)
      for (int f = 0; f < 2; ++f) all.emplace_back(v, f);
    from_candidates.UpdateFromCandidates(s.X, 0.01, all);
    for (const VertexFaceProximity* p : {&prox, &from_candidates}) {
      if (c.inside) {
        ASSERT_EQ(p->pairs().size(), 1u);
        EXPECT_EQ(p->pairs()[0].vertex, 6);
        EXPECT_EQ(p->pairs()[0].face, 0);
      } else {
        EXPECT_TRUE(p->pairs().empty()) << p->pairs().size() << " pairs, the first (" << p->pairs()[0].vertex
                                        << ", " << p->pairs()[0].face << ")";
      }
    }
  }
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
