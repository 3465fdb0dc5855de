// The crossing resolver puts back what passed through during a step, and its vertex-face
// candidates cover every pair within the broad-phase reach at the end positions (the simulator
// reuses them as the next step's proximity pairs).
#include <cmath>
#include <random>
#include <set>
#include <utility>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "sim/crossing_resolver.h"
#include "sim/test_grid_faces.h"
#include "sim/vertex_face_proximity.h"

namespace clothwind::sim {
namespace {

// Signed distance of p from the plane of triangle (a, b, c) along its normal.
double SideOf(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return (b - a).cross(c - a).normalized().dot(p - a);
}

TEST(CrossingResolver, VertexThatJumpedThroughAFaceGoesBackToItsSide) {
  // Face 0 in z = 0; vertex 3 (of the far-away face 1) moves from 5 mm above to 5 mm below it.
  Eigen::MatrixX3i F(2, 3);
  F << 0, 1, 2, 3, 4, 5;
  Eigen::MatrixX3d X0(6, 3);
  X0 << 0, 0, 0, 0.2, 0, 0, 0, 0.2, 0, 0.05, 0.05, 0.005, 0.5, 0.5, 0.3, 0.5, 0.7, 0.3;
  Eigen::MatrixX3d X = X0, V = Eigen::MatrixX3d::Zero(6, 3);
  X(3, 2) = -0.005;
  V(3, 2) = -2.0;
  CrossingResolver resolver(F, Eigen::VectorXd::Ones(6));
  EXPECT_GE(resolver.Resolve(X0, 0.002, 0.002, 8, &X, &V), 1);
  // The face tilts a little (its corners move by their weights), hence the tolerance.
  EXPECT_GE(SideOf(X.row(3), X.row(0), X.row(1), X.row(2)), 0.002 * 0.99);
  // No longer approaching: the vertex against the face point it crossed (weights 0.5, 0.25, 0.25).
  EXPECT_GE(V(3, 2) - (0.5 * V(0, 2) + 0.25 * V(1, 2) + 0.25 * V(2, 2)), -1e-12);
  // Momentum kept (equal masses).
  EXPECT_NEAR(V.col(2).sum(), -2.0, 1e-12);
}

// Nodes of unequal mass (a boundary node carries less cloth than an interior one): the impulse
// that puts a vertex back moves each node by its inverse mass, so momentum and the centre of
// mass are kept. The test above has equal masses, where a resolver that ignored them passed.
TEST(CrossingResolver, UnequalMassesKeepMomentumAndTheCentreOfMass) {
  Eigen::MatrixX3i F(2, 3);
  F << 0, 1, 2, 3, 4, 5;
  Eigen::MatrixX3d X0(6, 3);
  X0 << 0, 0, 0, 0.2, 0, 0, 0, 0.2, 0, 0.05, 0.05, 0.005, 0.5, 0.5, 0.3, 0.5, 0.7, 0.3;
  Eigen::VectorXd inverse_mass(6);
  inverse_mass << 2.0, 0.5, 1.0, 4.0, 1.0, 1.0;
  const Eigen::VectorXd mass = inverse_mass.cwiseInverse();
  Eigen::MatrixX3d X = X0, V = Eigen::MatrixX3d::Zero(6, 3);
  X(3, 2) = -0.005;
  V(3, 2) = -2.0;
  V(0, 0) = 0.3;  // the face moving too, sideways
  const Eigen::RowVector3d momentum = mass.transpose() * V, centre = mass.transpose() * X;
  CrossingResolver resolver(F, inverse_mass);
  ASSERT_GE(resolver.Resolve(X0, 0.002, 0.002, 8, &X, &V), 1);
  EXPECT_GE(SideOf(X.row(3), X.row(0), X.row(1), X.row(2)), 0.002 * 0.99);
  EXPECT_LT((mass.transpose() * V - momentum).norm(), 1e-12) << mass.transpose() * V;
  EXPECT_LT((mass.transpose() * X - centre).norm(), 1e-12) << mass.transpose() * X;
}

TEST(CrossingResolver, EdgesThatPassedThroughEachOtherGoBack) {
  // Edge (0, 1) along x at z = 0; edge (3, 4) along y moves from z = +5 mm to z = -5 mm across it.
  Eigen::MatrixX3i F(2, 3);
  F << 0, 1, 2, 3, 4, 5;
  Eigen::MatrixX3d X0(6, 3);
  X0 << -0.1, 0, 0, 0.1, 0, 0, 0, -0.3, 0,  // face 0's third vertex away from the crossing
      0, -0.1, 0.005, 0, 0.1, 0.005, -0.3, 0, 0.3;
  Eigen::MatrixX3d X = X0, V = Eigen::MatrixX3d::Zero(6, 3);
  X(3, 2) = X(4, 2) = -0.005;
  CrossingResolver resolver(F, Eigen::VectorXd::Ones(6));
  EXPECT_GE(resolver.Resolve(X0, 0.002, 0.002, 8, &X, &V), 1);
  // Edge (3, 4) is above edge (0, 1) again where they cross.
  EXPECT_GT(0.5 * (X(3, 2) + X(4, 2)) - 0.5 * (X(0, 2) + X(1, 2)), 0.001);
}

TEST(CrossingResolver, VertexFaceCandidatesCoverEveryPairWithinReach) {
  // A sheet folded over itself (two layers ~8 mm apart), jittered, moving a little at random:
  // every proximity pair at the end positions is a candidate.
  const int n = 8;
  const Eigen::MatrixX3i F = GridFaces(n);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixX3d X0(n * n, 3);
  for (int i = 0; i < n * n; ++i) {
    const int row = i / n;
    const bool upper = row >= n / 2;
    X0.row(i) << (upper ? 0.05 * (n - 1 - row) + 0.01 : 0.05 * row) + 0.01 * u(rng), 0.05 * (i % n) + 0.01 * u(rng),
        (upper ? 0.008 : 0.0) + 0.002 * u(rng);
  }
  Eigen::MatrixX3d X = X0;
  for (int i = 0; i < n * n; ++i) X.row(i) += 0.002 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
  const double reach = 0.01;
  CrossingResolver resolver(F, Eigen::VectorXd::Ones(n * n));
  Eigen::MatrixX3d V = Eigen::MatrixX3d::Zero(n * n, 3);
  ASSERT_EQ(resolver.Resolve(X0, 0.0, reach, 1, &X, &V), 0) << "the guarantee holds when nothing was corrected";
  const std::set<std::pair<int, int>> candidates(resolver.vertex_face_candidates().begin(),
                                                 resolver.vertex_face_candidates().end());
  EXPECT_EQ(candidates.size(), resolver.vertex_face_candidates().size()) << "each pair once";
  VertexFaceProximity proximity(F, n * n, 0.05);
  proximity.Update(X, reach);
  ASSERT_GT(proximity.pairs().size(), 5u) << "the test needs pairs within reach";
  for (const auto& p : proximity.pairs())
    EXPECT_TRUE(candidates.count({p.vertex, p.face})) << "vertex " << p.vertex << ", face " << p.face;
}

// Swept boxes of points of X0 and X1 overlap when grown by reach (the broad phase's criterion).
bool SweptBoxesNear(const std::vector<int>& a, const std::vector<int>& b, const Eigen::MatrixX3d& X0,
                    const Eigen::MatrixX3d& X1, double reach) {
  Eigen::AlignedBox3d ba, bb;
  for (int i : a) ba.extend(X0.row(i).transpose()).extend(X1.row(i).transpose());
  for (int i : b) bb.extend(X0.row(i).transpose()).extend(X1.row(i).transpose());
  return (ba.min().array() <= bb.max().array() + reach).all() && (bb.min().array() <= ba.max().array() + reach).all();
}

TEST(CrossingResolver, CandidatesAreThePairsWhoseSweptBoxesMeetAsBruteForceFindsThem) {
  // A sheet rolled into a tight spiral (layers 12 mm apart, so faces far apart in the sheet meet)
  // and crumpled, moving at random: the candidates must be every vertex-face and edge-edge pair
  // (no shared vertex) whose swept boxes come within reach, once each, and no pair farther than
  // the reach plus the float padding: the neighbours-in-the-sheet lists and the sweep together
  // equal a search over all pairs.
  const int n = 12;
  const Eigen::MatrixX3i F = GridFaces(n);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixX3d X0(n * n, 3);
  for (int i = 0; i < n * n; ++i) {
    const double s = 0.04 * (i / n), angle = s / 0.05;  // arc length along a spiral r = 0.05 + 0.012 angle / 2pi
    const double r = 0.05 + 0.012 * angle / (2 * M_PI);
    X0.row(i) << r * std::cos(angle) + 0.004 * u(rng), r * std::sin(angle) + 0.004 * u(rng),
        0.04 * (i % n) + 0.004 * u(rng);
  }
  Eigen::MatrixX3d X1 = X0;
  for (int i = 0; i < n * n; ++i) X1.row(i) += 0.006 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
  const double reach = 0.01;
  CrossingResolver resolver(F, Eigen::VectorXd::Ones(n * n));
  Eigen::MatrixX3d X = X1, V = Eigen::MatrixX3d::Zero(n * n, 3);
  resolver.Resolve(X0, 0.0, reach, 1, &X, &V);

  std::set<std::pair<int, int>> expected_vf, expected_ee;
  int far_pairs = 0;  // vertex-face pairs whose vertex is not on a face sharing a vertex with the face
  for (int f = 0; f < F.rows(); ++f)
    for (int v = 0; v < n * n; ++v) {
      if (F(f, 0) == v || F(f, 1) == v || F(f, 2) == v) continue;
      if (SweptBoxesNear({v}, {F(f, 0), F(f, 1), F(f, 2)}, X0, X1, reach)) {
        expected_vf.insert({v, f});
        far_pairs += std::abs(v / n - F(f, 0) / n) >= 3;  // rows apart in the sheet
      }
    }
  const auto& edges = resolver.edges();
  for (size_t i = 0; i < edges.size(); ++i)
    for (size_t j = i + 1; j < edges.size(); ++j) {
      const auto [a, b] = edges[i];
      const auto [c, d] = edges[j];
      if (a == c || a == d || b == c || b == d) continue;
      if (SweptBoxesNear({a, b}, {c, d}, X0, X1, reach)) expected_ee.insert({static_cast<int>(i), static_cast<int>(j)});
    }
  ASSERT_GT(far_pairs, 20) << "the spiral's layers must meet for the test to see far pairs";

  const auto& vf = resolver.vertex_face_candidates();
  const auto& ee = resolver.edge_edge_candidates();
  const std::set<std::pair<int, int>> got_vf(vf.begin(), vf.end()), got_ee(ee.begin(), ee.end());
  EXPECT_EQ(got_vf.size(), vf.size()) << "each vertex-face pair once";
  EXPECT_EQ(got_ee.size(), ee.size()) << "each edge pair once";
  for (const auto& p : expected_vf) EXPECT_TRUE(got_vf.count(p)) << "missed vertex " << p.first << ", face " << p.second;
  for (const auto& p : expected_ee) EXPECT_TRUE(got_ee.count(p)) << "missed edges " << p.first << ", " << p.second;
  const double loose = reach + 2 * CrossingResolver::kBoxPadding;
  for (const auto& [v, f] : got_vf)
    EXPECT_TRUE(SweptBoxesNear({v}, {F(f, 0), F(f, 1), F(f, 2)}, X0, X1, loose)) << "vertex " << v << ", face " << f;
  for (const auto& [i, j] : got_ee) {
    EXPECT_LT(i, j);
    EXPECT_TRUE(SweptBoxesNear({edges[i].first, edges[i].second}, {edges[j].first, edges[j].second}, X0, X1, loose));
  }
}

}  // namespace
}  // namespace clothwind::sim
