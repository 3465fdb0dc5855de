#include "sim/strain_limiter.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace clothwind::sim {

StrainLimiter::StrainLimiter(const Mesh& mesh, const Eigen::VectorXd& mass,
                             const std::vector<char>& pinned) {
  faces_.resize(mesh.F.rows());
  for (int f = 0; f < mesh.F.rows(); ++f) {
    Face& face = faces_[f];
    Eigen::Vector2d u[3];
    double wsum = 0;
    Eigen::Vector2d uc = Eigen::Vector2d::Zero();
    for (int c = 0; c < 3; ++c) {
      face.v[c] = mesh.F(f, c);
      u[c] = mesh.U.row(face.v[c]).transpose();
      face.pinned[c] = pinned[face.v[c]] != 0;
      face.w[c] = pinned[face.v[c]] ? 1e9 * mass.maxCoeff() : mass[face.v[c]];
      wsum += face.w[c];
      uc += face.w[c] * u[c];
    }
    uc /= wsum;
    for (int c = 0; c < 3; ++c) face.du[c] = u[c] - uc;
    Eigen::Matrix2d Dm;
    Dm.col(0) = u[1] - u[0];
    Dm.col(1) = u[2] - u[0];
    face.Dm_inv = Dm.inverse();
  }
}

int StrainLimiter::Project(double strain_min, double strain_max, int iterations, double dt,
                           Eigen::MatrixX3d* xp, Eigen::MatrixX3d* vp) {
  Eigen::MatrixX3d& x = *xp;
  before_ = x;
  // Squared limits with a small slack so converged faces are not touched again.
  const double lo2 = strain_min > 0 ? strain_min * strain_min * (1 - 1e-6) : -1.0;
  const double hi2 = std::isfinite(strain_max) ? strain_max * strain_max * (1 + 1e-6) : 1e300;
  int initially_violated = 0;
  // After the first sweep only faces with a vertex moved by the previous sweep can be violated.
  moved_.assign(x.rows(), 1);
  moved_next_.assign(x.rows(), 0);
  for (int sweep = 0; sweep < iterations; ++sweep) {
    int violated = 0;
    for (const Face& face : faces_) {
      if (!moved_[face.v[0]] && !moved_[face.v[1]] && !moved_[face.v[2]]) continue;
      const Eigen::Vector3d x0 = x.row(face.v[0]), x1 = x.row(face.v[1]), x2 = x.row(face.v[2]);
      Eigen::Matrix<double, 3, 2> Ds;
      Ds.col(0) = x1 - x0;
      Ds.col(1) = x2 - x0;
      const Eigen::Matrix<double, 3, 2> F = Ds * face.Dm_inv;
      // Eigenvalues of C = F^T F in closed form (cheap rejection of faces within limits).
      const double c00 = F.col(0).squaredNorm(), c11 = F.col(1).squaredNorm(),
                   c01 = F.col(0).dot(F.col(1));
      const double mean = 0.5 * (c00 + c11);
      const double rad = std::sqrt(0.25 * (c00 - c11) * (c00 - c11) + c01 * c01);
      const double l_hi = mean + rad, l_lo = mean - rad;
      if (l_hi <= hi2 && l_lo >= lo2) continue;
      if (!(l_lo > 1e-16)) continue;  // collapsed face: no meaningful direction to restore
      ++violated;
      // Eigenvectors of C: V = [e_hi, e_lo].
      Eigen::Vector2d e_hi;
      if (std::abs(c01) > 1e-300) {
        e_hi = Eigen::Vector2d(l_hi - c11, c01).normalized();
      } else {
        e_hi = c00 >= c11 ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 1);
      }
      const Eigen::Vector2d e_lo(-e_hi.y(), e_hi.x());
      const double s_hi = std::sqrt(l_hi), s_lo = std::sqrt(l_lo);
      auto clampv = [&](double s) {
        if (strain_min > 0) s = std::max(s, strain_min);
        if (std::isfinite(strain_max)) s = std::min(s, strain_max);
        return s;
      };
      // F' = F V diag(s'/s) V^T.
      const Eigen::Matrix<double, 3, 2> Fn =
          (F * e_hi) * (clampv(s_hi) / s_hi) * e_hi.transpose() +
          (F * e_lo) * (clampv(s_lo) / s_lo) * e_lo.transpose();
      const double wsum = face.w[0] + face.w[1] + face.w[2];
      const Eigen::Vector3d xc = (face.w[0] * x0 + face.w[1] * x1 + face.w[2] * x2) / wsum;
      for (int c = 0; c < 3; ++c)
        if (!face.pinned[c]) {
          x.row(face.v[c]) = (xc + Fn * face.du[c]).transpose();
          moved_next_[face.v[c]] = 1;
        }
    }
    if (sweep == 0) initially_violated = violated;
    if (violated == 0) break;
    moved_.swap(moved_next_);
    std::fill(moved_next_.begin(), moved_next_.end(), 0);
  }
  *vp += (x - before_) / dt;
  return initially_violated;
}

}  // namespace clothwind::sim
