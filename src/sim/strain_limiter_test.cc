#include "sim/strain_limiter.h"

#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <gtest/gtest.h>

#include "common/random.h"

namespace clothwind::sim {
namespace {

// One free triangle, rest shape the unit right triangle (so the deformation gradient's columns
// are the edges x1 - x0 and x2 - x0).
Mesh UnitTriangle() {
  Mesh m;
  m.U.resize(3, 2);
  m.U << 0, 0, 1, 0, 0, 1;
  m.V = Eigen::MatrixX3d::Zero(3, 3);
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  return m;
}

// The principal stretches (singular values of the 3x2 deformation gradient), largest first.
Eigen::Vector2d Stretches(const Eigen::MatrixX3d& x) {
  Eigen::Matrix<double, 3, 2> F;
  F.col(0) = (x.row(1) - x.row(0)).transpose();
  F.col(1) = (x.row(2) - x.row(0)).transpose();
  return Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(F).singularValues();
}

TEST(StrainLimiter, AFaceLargestAlongVWithRoundOffShearIsLimitedAlongV) {
  // Compressed to 0.775 along material u and 0.941 along v, with a shear term c01 at round-off
  // size: the largest stretch's direction used to be formed from (l_hi - c11, c01), rounding
  // noise here, so it could point along u and the projection clamped the wrong stretches (the
  // face stayed outside the limits).
  Mesh m = UnitTriangle();
  Eigen::MatrixX3d x(3, 3), v = Eigen::MatrixX3d::Zero(3, 3);
  const double su = 0.77468602906984296, sv = 0.94110995320659607, shear = -1.5245495905270046e-16;
  x << 0, 0, 0, su, shear, 0, shear, sv, 0;
  StrainLimiter limiter(m, Eigen::VectorXd::Ones(3), {0, 0, 0});
  EXPECT_EQ(limiter.Project(0.95, 1.05, 1, 0.01, &x, &v), 1);
  const Eigen::Vector2d s = Stretches(x);
  EXPECT_NEAR(s[0], 0.95, 1e-9);
  EXPECT_NEAR(s[1], 0.95, 1e-9);
}

TEST(StrainLimiter, OneProjectionBringsAnyFreeFaceWithinLimitsAndKeepsItsCentroid) {
  // A lone face needs one projection whatever its shape and orientation, including nearly
  // axis-aligned ones; the mass-weighted centroid (the face's momentum, with v) does not move.
  Rng rng(7);
  Mesh m = UnitTriangle();
  const Eigen::VectorXd mass = (Eigen::VectorXd(3) << 1.0, 2.0, 3.0).finished();
  StrainLimiter limiter(m, mass, {0, 0, 0});
  for (int trial = 0; trial < 2000; ++trial) {
    const double su = rng.Uniform(0.7, 1.4), sv = rng.Uniform(0.7, 1.4);
    const double shear = trial % 2 ? rng.Uniform(-1e-15, 1e-15) : rng.Uniform(-0.2, 0.2);
    Eigen::MatrixX3d x(3, 3), v = Eigen::MatrixX3d::Zero(3, 3);
    x << 0, 0, 0, su, shear, 0, shear, sv, 0;
    const Eigen::RowVector3d centroid = mass.transpose() * x / mass.sum();
    limiter.Project(0.95, 1.05, 1, 0.01, &x, &v);
    const Eigen::Vector2d s = Stretches(x);
    ASSERT_LE(s[0], 1.05 + 1e-9) << "trial " << trial << " su " << su << " sv " << sv << " shear " << shear;
    ASSERT_GE(s[1], 0.95 - 1e-9) << "trial " << trial << " su " << su << " sv " << sv << " shear " << shear;
    ASSERT_LT((mass.transpose() * x / mass.sum() - centroid).norm(), 1e-12) << "trial " << trial;
    // The velocity change is the position change over the time step: momentum kept too.
    ASSERT_LT((mass.transpose() * v).norm(), 1e-9) << "trial " << trial;
  }
}

// The 3x2 deformation gradient of UnitTriangle's face at positions x.
Eigen::Matrix<double, 3, 2> Gradient(const Eigen::MatrixX3d& x) {
  Eigen::Matrix<double, 3, 2> F;
  F.col(0) = (x.row(1) - x.row(0)).transpose();
  F.col(1) = (x.row(2) - x.row(0)).transpose();
  return F;
}

// UnitTriangle's corners placed with deformation gradient F = R [diag(s) ; 0] V^T: principal
// stretches s, their material directions V (the u axis turned by `material_angle`), turned into
// space by R, then moved by `offset`.
Eigen::MatrixX3d PlacedTriangle(const Eigen::Vector2d& s, double material_angle, const Eigen::Matrix3d& R,
                                const Eigen::Vector3d& offset) {
  const Eigen::Matrix2d V = Eigen::Rotation2Dd(material_angle).toRotationMatrix();
  Eigen::Matrix<double, 3, 2> S = Eigen::Matrix<double, 3, 2>::Zero();
  S(0, 0) = s[0];
  S(1, 1) = s[1];
  const Eigen::Matrix<double, 3, 2> F = R * S * V.transpose();
  Eigen::MatrixX3d x(3, 3);
  x.row(0) = offset.transpose();
  x.row(1) = (offset + F.col(0)).transpose();
  x.row(2) = (offset + F.col(1)).transpose();
  return x;
}

TEST(StrainLimiter, AFaceStretchedPastTheLimitEndsExactlyAtItWithItsDirectionsKept) {
  // Principal stretches (1.2, 1.0), the stretch along a material direction 0.3 rad off the u axis
  // and the face turned in space: the projection is to the closest shape within the limits, which
  // keeps both singular-vector frames and clamps only the singular value that is out: F' = F M,
  // M = V diag(1.05 / 1.2, 1) V^T. (Projecting too far, e.g. to 1, or turning the face, fails.)
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const double angle = 0.3;
  Mesh m = UnitTriangle();
  const Eigen::VectorXd mass = (Eigen::VectorXd(3) << 1.0, 2.0, 3.0).finished();
  StrainLimiter limiter(m, mass, {0, 0, 0});
  for (const auto& [before, after] : {std::make_pair(Eigen::Vector2d(1.2, 1.0), Eigen::Vector2d(1.05, 1.0)),
                                      std::make_pair(Eigen::Vector2d(1.0, 0.9), Eigen::Vector2d(1.0, 0.95)),
                                      std::make_pair(Eigen::Vector2d(1.2, 0.9), Eigen::Vector2d(1.05, 0.95))}) {
    SCOPED_TRACE("stretches " + std::to_string(before[0]) + ", " + std::to_string(before[1]));
    Eigen::MatrixX3d x = PlacedTriangle(before, angle, R, Eigen::Vector3d(0.3, -0.1, 2.0));
    Eigen::MatrixX3d v = Eigen::MatrixX3d::Zero(3, 3);
    const Eigen::Matrix<double, 3, 2> F = Gradient(x);
    EXPECT_EQ(limiter.Project(0.95, 1.05, 1, 0.01, &x, &v), 1);
    const Eigen::Vector2d s = Stretches(x);
    EXPECT_NEAR(s[0], after[0], 1e-12);
    EXPECT_NEAR(s[1], after[1], 1e-12);
    const Eigen::Matrix2d V = Eigen::Rotation2Dd(angle).toRotationMatrix();
    const Eigen::Vector2d ratio(after[0] / before[0], after[1] / before[1]);
    const Eigen::Matrix2d M = V * ratio.asDiagonal() * V.transpose();
    EXPECT_LT((Gradient(x) - F * M).norm(), 1e-12) << "the stretch directions changed:\n" << Gradient(x);
  }
}

TEST(StrainLimiter, AFaceWithinTheLimitsIsLeftBitIdentical) {
  // Re-projecting a face that is within its limits would only add round-off (and velocity noise,
  // and work): it must not be touched at all, position nor velocity.
  Rng rng(3);
  Mesh m = UnitTriangle();
  StrainLimiter limiter(m, (Eigen::VectorXd(3) << 1.0, 2.0, 3.0).finished(), {0, 0, 0});
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector2d s(rng.Uniform(0.951, 1.049), rng.Uniform(0.951, 1.049));
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(rng.Uniform(0, 6.28), Eigen::Vector3d(rng.Normal(), rng.Normal(), rng.Normal()).normalized())
            .toRotationMatrix();
    Eigen::MatrixX3d x = PlacedTriangle(s, rng.Uniform(0, 3.14), R, Eigen::Vector3d(rng.Normal(), rng.Normal(), 1));
    Eigen::MatrixX3d v(3, 3);
    for (int i = 0; i < 9; ++i) v(i / 3, i % 3) = rng.Normal();
    const Eigen::MatrixX3d x0 = x, v0 = v;
    ASSERT_EQ(limiter.Project(0.95, 1.05, 4, 0.01, &x, &v), 0) << "trial " << trial;
    ASSERT_TRUE(x == x0) << "trial " << trial << ": moved by " << (x - x0).norm();
    ASSERT_TRUE(v == v0) << "trial " << trial << ": velocity changed by " << (v - v0).norm();
  }
}

TEST(StrainLimiter, TheVelocityChangeIsThePositionChangeOverTheTimeStep) {
  // ArcSim's rule, component by component: v += (x' - x) / dt, on every vertex, pinned ones
  // unchanged (they do not move). A half (or no) velocity update keeps the momentum test above
  // passing (it is zero either way) but leaves the cloth moving at a speed its positions deny.
  Rng rng(5);
  Mesh m;
  m.U.resize(4, 2);
  m.U << 0, 0, 1, 0, 1, 1, 0, 1;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  const Eigen::VectorXd mass = (Eigen::VectorXd(4) << 1.0, 2.0, 1.5, 0.5).finished();
  StrainLimiter limiter(m, mass, {0, 0, 0, 1});  // vertex 3 pinned
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::MatrixX3d x(4, 3), v(4, 3);
    for (int i = 0; i < 4; ++i) {
      x.row(i) << 1.3 * m.U(i, 0), 0.8 * m.U(i, 1), 0;  // out of limits both ways
      for (int c = 0; c < 3; ++c) {
        x(i, c) += rng.Uniform(-0.05, 0.05);
        v(i, c) = rng.Normal();
      }
    }
    const Eigen::MatrixX3d x0 = x, v0 = v;
    const double dt = rng.Uniform(0.001, 0.02);
    ASSERT_GT(limiter.Project(0.95, 1.05, 4, dt, &x, &v), 0);
    ASSERT_GT((x - x0).norm(), 0.05) << "the test should move the vertices";
    EXPECT_TRUE(x.row(3) == x0.row(3) && v.row(3) == v0.row(3)) << "the pinned vertex moved";
    for (int i = 0; i < 4; ++i)
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(v(i, c) - v0(i, c), (x(i, c) - x0(i, c)) / dt, 1e-12 * (1 + std::abs(x(i, c) - x0(i, c)) / dt))
            << "trial " << trial << ", vertex " << i << ", component " << c;
  }
}

}  // namespace
}  // namespace clothwind::sim
