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
    for (int c = 0; c < 3; ++c) face.w[c] /= wsum;  // normalised: the centroid is a plain weighted sum
    for (int c = 0; c < 3; ++c) face.du[c] = u[c] - uc;
    Eigen::Matrix2d Dm;
    Dm.col(0) = u[1] - u[0];
    Dm.col(1) = u[2] - u[0];
    face.Dm_inv = Dm.inverse();
  }
}

StrainLimitResult StrainLimiter::Project(const StrainLimitSettings& settings, double dt,
                                         Eigen::MatrixX3d* xp, Eigen::MatrixX3d* vp) {
  Eigen::MatrixX3d& x = *xp;
  const int n = static_cast<int>(x.rows());
  const double strain_min = settings.min, strain_max = settings.max;
  const bool has_min = strain_min > 0, has_max = std::isfinite(strain_max);
  // Work on an interleaved copy (x, y, z of a vertex adjacent in memory).
  work_.resize(3 * n);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) work_[3 * i + c] = x(i, c);
  double* X = work_.data();
  // Squared limits with a small slack so faces just projected are not touched again...
  const double lo2 = has_min ? strain_min * strain_min * (1 - 1e-6) : -1.0;
  const double hi2 = has_max ? strain_max * strain_max * (1 + 1e-6) : 1e300;
  // ...and the tolerance that ends the sweeps (a face outside by less is projected but does not
  // keep the sweeps going).
  const double lo2_tol = has_min ? lo2 * (1 - settings.tolerance) * (1 - settings.tolerance) : -1.0;
  const double hi2_tol = has_max ? hi2 * (1 + settings.tolerance) * (1 + settings.tolerance) : 1e300;
  auto clamp = [&](double s) {
    if (has_min) s = std::max(s, strain_min);
    if (has_max) s = std::min(s, strain_max);
    return s;
  };
  StrainLimitResult result;
  // After the first sweep only faces with a vertex moved by the previous sweep can be violated.
  moved_.assign(n, 1);
  moved_next_.assign(n, 0);
  for (int sweep = 0; sweep < settings.max_sweeps; ++sweep) {
    int projected = 0, violated = 0;
    double excess = 0;
    for (const Face& face : faces_) {
      if (!moved_[face.v[0]] && !moved_[face.v[1]] && !moved_[face.v[2]]) continue;
      const double* x0 = X + 3 * face.v[0];
      const double* x1 = X + 3 * face.v[1];
      const double* x2 = X + 3 * face.v[2];
      const Eigen::Matrix2d& D = face.Dm_inv;
      double Fu[3], Fv[3];
      for (int r = 0; r < 3; ++r) {
        const double e1 = x1[r] - x0[r], e2 = x2[r] - x0[r];
        Fu[r] = e1 * D(0, 0) + e2 * D(1, 0);
        Fv[r] = e1 * D(0, 1) + e2 * D(1, 1);
      }
      // Eigenvalues of C = F^T F in closed form (cheap rejection of faces within limits).
      const double c00 = Fu[0] * Fu[0] + Fu[1] * Fu[1] + Fu[2] * Fu[2];
      const double c11 = Fv[0] * Fv[0] + Fv[1] * Fv[1] + Fv[2] * Fv[2];
      const double c01 = Fu[0] * Fv[0] + Fu[1] * Fv[1] + Fu[2] * Fv[2];
      const double mean = 0.5 * (c00 + c11);
      const double rad2 = 0.25 * (c00 - c11) * (c00 - c11) + c01 * c01;
      // Within limits iff mean + rad <= hi2 and mean - rad >= lo2: decided without a square root.
      const double room = std::min(hi2 - mean, mean - lo2);
      if (room >= 0 && rad2 <= room * room) continue;
      const double rad = std::sqrt(rad2);
      const double l_hi = mean + rad, l_lo = mean - rad;
      if (l_hi <= hi2 && l_lo >= lo2) continue;
      if (!(l_lo > 1e-16)) continue;  // collapsed face: no meaningful direction to restore
      ++projected;
      if (l_hi > hi2_tol || l_lo < lo2_tol) ++violated;
      // Eigenvectors of C: e_hi, e_lo = perp(e_hi).
      double eh0, eh1;
      if (std::abs(c01) > 1e-300) {
        // Either row of (C - l_hi I) v = 0 gives the direction; take the one whose entries are
        // not a difference of nearly equal numbers (with c01 at round-off size, l_hi - c11 is
        // pure rounding noise when the face stretches most along v).
        if (c00 >= c11) {
          eh0 = l_hi - c11;
          eh1 = c01;
        } else {
          eh0 = c01;
          eh1 = l_hi - c00;
        }
        const double inv = 1.0 / std::sqrt(eh0 * eh0 + eh1 * eh1);
        eh0 *= inv;
        eh1 *= inv;
      } else if (c00 >= c11) {
        eh0 = 1;
        eh1 = 0;
      } else {
        eh0 = 0;
        eh1 = 1;
      }
      const double el0 = -eh1, el1 = eh0;
      const double s_hi = std::sqrt(l_hi), s_lo = std::sqrt(l_lo);
      if (has_max) excess = std::max(excess, s_hi / strain_max - 1);
      if (has_min) excess = std::max(excess, 1 - s_lo / strain_min);
      const double r_hi = clamp(s_hi) / s_hi, r_lo = clamp(s_lo) / s_lo;
      // F' = F M, M = V diag(r) V^T (2 by 2, symmetric).
      const double m00 = r_hi * eh0 * eh0 + r_lo * el0 * el0;
      const double m01 = r_hi * eh0 * eh1 + r_lo * el0 * el1;
      const double m11 = r_hi * eh1 * eh1 + r_lo * el1 * el1;
      double xc[3];
      for (int r = 0; r < 3; ++r) xc[r] = face.w[0] * x0[r] + face.w[1] * x1[r] + face.w[2] * x2[r];
      for (int c = 0; c < 3; ++c) {
        if (face.pinned[c]) continue;
        // x_c' = xc + F M du_c.
        const double a = m00 * face.du[c].x() + m01 * face.du[c].y();
        const double b = m01 * face.du[c].x() + m11 * face.du[c].y();
        double* xv = X + 3 * face.v[c];
        for (int r = 0; r < 3; ++r) xv[r] = xc[r] + Fu[r] * a + Fv[r] * b;
        moved_next_[face.v[c]] = 1;
      }
    }
    if (sweep == 0) result.initially_violated = projected;
    result.sweeps = sweep + 1;
    result.excess = excess;
    if (violated == 0) {
      result.converged = true;
      break;
    }
    moved_.swap(moved_next_);
    std::fill(moved_next_.begin(), moved_next_.end(), 0);
  }
  const double inv_dt = 1.0 / dt;
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const double moved = X[3 * i + c] - x(i, c);
      (*vp)(i, c) += moved * inv_dt;
      x(i, c) = X[3 * i + c];
    }
  return result;
}

}  // namespace clothwind::sim
