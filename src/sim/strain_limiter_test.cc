#include "sim/strain_limiter.h"

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

}  // namespace
}  // namespace clothwind::sim
