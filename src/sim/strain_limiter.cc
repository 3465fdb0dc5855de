#include "sim/strain_limiter.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/LU>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace clothwind::sim {

namespace {

// The limits as the projections test them.
struct Limits {
  explicit Limits(const StrainLimitSettings& settings)
      : strain_min(settings.min),
        strain_max(settings.max),
        has_min(strain_min > 0),
        has_max(std::isfinite(strain_max)),
        // Squared limits with a small slack so faces just projected are not touched again...
        lo2(has_min ? strain_min * strain_min * (1 - 1e-6) : -1.0),
        hi2(has_max ? strain_max * strain_max * (1 + 1e-6) : 1e300),
        // ...and the tolerance that ends the sweeps (a face outside by less is projected but does
        // not keep the sweeps going).
        lo2_tol(has_min ? lo2 * (1 - settings.tolerance) * (1 - settings.tolerance) : -1.0),
        hi2_tol(has_max ? hi2 * (1 + settings.tolerance) * (1 + settings.tolerance) : 1e300) {}
  double clamp(double s) const {
    if (has_min) s = std::max(s, strain_min);
    if (has_max) s = std::min(s, strain_max);
    return s;
  }
  double strain_min, strain_max;
  bool has_min, has_max;
  double lo2, hi2, lo2_tol, hi2_tol;
};

// One face's projection: its deformation gradient F = [Fu Fv] (3 by 2) and the 2 by 2 symmetric
// M = V diag(r) V^T with F M the shape whose stretches are clamped to the limits.
struct FaceProjection {
  double Fu[3], Fv[3];
  double m00, m01, m11;
  bool violated;  // outside the limits by more than the tolerance
  double excess;  // max(0, s_max / max - 1, 1 - s_min / min)
};

// Whether the shape F = [p->Fu p->Fv] (3 by 2) is outside the limits (and not collapsed); if so
// the rest of *p is its projection.
bool ProjectShape(const Limits& limits, FaceProjection* p) {
  const double* Fu = p->Fu;
  const double* Fv = p->Fv;
  // Eigenvalues of C = F^T F in closed form (cheap rejection of faces within limits).
  const double c00 = Fu[0] * Fu[0] + Fu[1] * Fu[1] + Fu[2] * Fu[2];
  const double c11 = Fv[0] * Fv[0] + Fv[1] * Fv[1] + Fv[2] * Fv[2];
  const double c01 = Fu[0] * Fv[0] + Fu[1] * Fv[1] + Fu[2] * Fv[2];
  const double mean = 0.5 * (c00 + c11);
  const double rad2 = 0.25 * (c00 - c11) * (c00 - c11) + c01 * c01;
  // Within limits iff mean + rad <= hi2 and mean - rad >= lo2: decided without a square root.
  const double room = std::min(limits.hi2 - mean, mean - limits.lo2);
  if (room >= 0 && rad2 <= room * room) return false;
  const double rad = std::sqrt(rad2);
  const double l_hi = mean + rad, l_lo = mean - rad;
  if (l_hi <= limits.hi2 && l_lo >= limits.lo2) return false;
  if (!(l_lo > 1e-16)) return false;  // collapsed face: no meaningful direction to restore
  p->violated = l_hi > limits.hi2_tol || l_lo < limits.lo2_tol;
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
  p->excess = 0;
  if (limits.has_max) p->excess = std::max(p->excess, s_hi / limits.strain_max - 1);
  if (limits.has_min) p->excess = std::max(p->excess, 1 - s_lo / limits.strain_min);
  const double r_hi = limits.clamp(s_hi) / s_hi, r_lo = limits.clamp(s_lo) / s_lo;
  // F' = F M, M = V diag(r) V^T (2 by 2, symmetric).
  p->m00 = r_hi * eh0 * eh0 + r_lo * el0 * el0;
  p->m01 = r_hi * eh0 * eh1 + r_lo * el0 * el1;
  p->m11 = r_hi * eh1 * eh1 + r_lo * el1 * el1;
  return true;
}

// Whether the face with vertices v[3] and inverse rest matrix Dm_inv, at interleaved positions X,
// is outside the limits (and not collapsed); p->Fu, Fv are its deformation gradient either way,
// and when it is outside the rest of *p is its projection.
template <typename FaceT>
bool ProjectFace(const FaceT& face, const double* X, const Limits& limits, FaceProjection* p) {
  const double* x0 = X + 3 * face.v[0];
  const double* x1 = X + 3 * face.v[1];
  const double* x2 = X + 3 * face.v[2];
  const Eigen::Matrix2d& D = face.Dm_inv;
  for (int r = 0; r < 3; ++r) {
    const double e1 = x1[r] - x0[r], e2 = x2[r] - x0[r];
    p->Fu[r] = e1 * D(0, 0) + e2 * D(1, 0);
    p->Fv[r] = e1 * D(0, 1) + e2 * D(1, 1);
  }
  return ProjectShape(limits, p);
}

}  // namespace

// kGlobal's weight of the fit to the faces' projections against the mass-weighted pull towards the
// positions before limiting (ADMM's penalty): a face's term is this times its mass times its area
// times |F - (z - u)|^2, of the order of its mass times the displacement squared. It sets how fast
// the iterations go, not where they end; on ArcSim's flag scene (stop 74, sim_bench, 30 iterations
// at most) 1e2 converged in 13-17 iterations a step, 1e3 in 7-15 but went unstable at 10 m/s with
// 10, and 1e4 stopped on shapes far from the anchor (droop 40 degrees at 1 m/s) before the
// dual-residual test existed.
constexpr double kGlobalStiffness = 1e2;

struct StrainLimiter::Global {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  std::vector<Eigen::Matrix<double, 2, 3>> B;  // per face: F_f(X)^T = B_f X_f
  double pin_weight = 0;                        // a pinned vertex's weight in the fit
  Eigen::MatrixX3d rhs, solved, anchor;  // #V by 3
  std::vector<Eigen::Matrix<double, 3, 2>> duals;  // per face: u_f (ADMM's scaled dual)
  std::vector<Eigen::Matrix<double, 3, 2>> projections;  // per face: z_f of the last iteration
  std::vector<FaceProjection> shapes;              // per face: F_f (and its projection) this iteration
  std::vector<double> best;                        // interleaved positions of the best iterate
};

StrainLimiter::StrainLimiter(const Mesh& mesh, const Eigen::VectorXd& mass,
                             const std::vector<char>& pinned)
    : mass_(mass), pinned_(pinned) {
  faces_.resize(mesh.F.rows());
  face_weight_.resize(mesh.F.rows());
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
    const double area = 0.5 * std::abs(Dm.determinant());
    face_weight_[f] = kGlobalStiffness * area * (mass[face.v[0]] + mass[face.v[1]] + mass[face.v[2]]) / 3.0;
  }
}

void StrainLimiter::PrepareGlobal() {
  if (global_) return;
  const int n = static_cast<int>(mass_.size());
  global_ = std::make_shared<Global>();
  // The global step minimises over positions X (each coordinate alike)
  //   sum_i w_i |X_i - anchor_i|^2 + sum_f c_f |F_f(X) - F*_f|^2,  F_f(X)^T = B_f X_f,
  // B_f = Dm_inv^T [-1 1 0; -1 0 1] (2 by 3), w_i the mass (huge when pinned): the normal
  // equations' matrix W + sum_f c_f B_f^T B_f is the same every step, factorised here once.
  Global& g = *global_;
  g.pin_weight = 1e9 * std::max(mass_.maxCoeff(), 1e-12);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(n + 9 * faces_.size());
  for (int i = 0; i < n; ++i) triplets.emplace_back(i, i, pinned_[i] ? g.pin_weight : mass_[i]);
  Eigen::Matrix<double, 2, 3> E;
  E << -1, 1, 0, -1, 0, 1;
  g.B.resize(faces_.size());
  for (size_t f = 0; f < faces_.size(); ++f) {
    const Face& face = faces_[f];
    g.B[f] = face.Dm_inv.transpose() * E;
    const Eigen::Matrix<double, 2, 3>& B = g.B[f];
    const Eigen::Matrix3d BtB = face_weight_[f] * B.transpose() * B;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) triplets.emplace_back(face.v[a], face.v[b], BtB(a, b));
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(triplets.begin(), triplets.end());
  global_->solver.compute(A);
  if (global_->solver.info() != Eigen::Success) {
    global_.reset();
    throw std::runtime_error("strain limiter: the global step's matrix could not be factorised");
  }
}

StrainLimitResult StrainLimiter::Sweep(const StrainLimitSettings& settings) {
  const int n = static_cast<int>(work_.size() / 3);
  const Limits limits(settings);
  double* X = work_.data();
  StrainLimitResult result;
  // After the first sweep only faces with a vertex moved by the previous sweep can be violated.
  moved_.assign(n, 1);
  moved_next_.assign(n, 0);
  for (int sweep = 0; sweep < settings.max_sweeps; ++sweep) {
    int projected = 0, violated = 0;
    double excess = 0;
    for (const Face& face : faces_) {
      if (!moved_[face.v[0]] && !moved_[face.v[1]] && !moved_[face.v[2]]) continue;
      FaceProjection p;
      if (!ProjectFace(face, X, limits, &p)) continue;
      ++projected;
      if (p.violated) ++violated;
      excess = std::max(excess, p.excess);
      const double* x0 = X + 3 * face.v[0];
      const double* x1 = X + 3 * face.v[1];
      const double* x2 = X + 3 * face.v[2];
      double xc[3];
      for (int r = 0; r < 3; ++r) xc[r] = face.w[0] * x0[r] + face.w[1] * x1[r] + face.w[2] * x2[r];
      for (int c = 0; c < 3; ++c) {
        if (face.pinned[c]) continue;
        // x_c' = xc + F M du_c.
        const double a = p.m00 * face.du[c].x() + p.m01 * face.du[c].y();
        const double b = p.m01 * face.du[c].x() + p.m11 * face.du[c].y();
        double* xv = X + 3 * face.v[c];
        for (int r = 0; r < 3; ++r) xv[r] = xc[r] + p.Fu[r] * a + p.Fv[r] * b;
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
  return result;
}

// Local/global iterations: ADMM on the projective-dynamics split (Overby et al. 2017), with the
// strain limits as each face's constraint set. It minimises sum_i m_i |x_i - anchor_i|^2 over
// positions whose faces are all within the limits, anchor the positions before limiting:
//   local   z_f = the projection of F_f + u_f onto the limits (FaceProjection), u_f += F_f - z_f
//   global  the positions that best fit every face's z_f - u_f, pulled towards the anchor by the
//           masses: one sparse solve with the matrix PrepareGlobal factorised
// The scaled duals u_f carry what a face still lacks into the next fit, so the limits are met
// exactly in the end whatever the fit's weight; without them (plain local/global) the anchors of
// a whole flag's vertices pulled against each face near the pole, and a strip stretched 10 %
// stayed 7.6 % over after 50 iterations. Each global step moves the whole sheet, so nothing
// creeps a face an iteration as the sweeps' corrections do.
StrainLimitResult StrainLimiter::LocalGlobal(const StrainLimitSettings& settings) {
  PrepareGlobal();
  Global& g = *global_;
  const int n = static_cast<int>(work_.size() / 3);
  const Limits limits(settings);
  double* X = work_.data();
  g.anchor.resize(n, 3);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) g.anchor(i, c) = X[3 * i + c];
  g.duals.assign(faces_.size(), Eigen::Matrix<double, 3, 2>::Zero());
  g.projections.resize(faces_.size());
  std::vector<FaceProjection>& shapes = g.shapes;
  shapes.resize(faces_.size());
  // Where the positions X stand: each face's shape (into `shapes`), and how many are projected
  // and violated, and by how much at most.
  struct Standing {
    int projected = 0, violated = 0;
    double excess = 0;
  };
  const auto measure = [&] {
    Standing s;
    for (size_t f = 0; f < faces_.size(); ++f) {
      if (!ProjectFace(faces_[f], X, limits, &shapes[f])) continue;
      ++s.projected;
      if (shapes[f].violated) ++s.violated;
      s.excess = std::max(s.excess, shapes[f].excess);
    }
    return s;
  };
  StrainLimitResult result;
  double z_change = 0;  // largest change of a face's projection z_f in the last iteration
  for (int iteration = 0; iteration < settings.max_sweeps; ++iteration) {
    // Where the positions stand: what the result reports, and whether to go on.
    const Standing standing = measure();
    const int violated = standing.violated;
    const double excess = standing.excess;
    if (iteration == 0) {
      result.initially_violated = standing.projected;
      // The first iteration's z_f are compared with the shapes they start from.
      for (size_t f = 0; f < faces_.size(); ++f)
        for (int r = 0; r < 3; ++r) {
          g.projections[f](r, 0) = shapes[f].Fu[r];
          g.projections[f](r, 1) = shapes[f].Fv[r];
        }
    }
    result.sweeps = iteration + 1;
    // Done when the positions are within the limits and the projections have settled (ADMM's
    // dual residual): feasibility alone stopped at the first shape within the limits however far
    // from the anchor, which with a stiff fit is the previous step's, and held the flag up (droop
    // 40 degrees at 1 m/s where ArcSim's hangs at 80).
    if (violated == 0 && (iteration == 0 || z_change <= std::max(settings.tolerance, 1e-6))) {
      result.excess = excess;
      result.converged = true;
      break;
    }
    z_change = 0;
    // The iterate nearest the limits so far is what an unconverged run returns: ADMM's iterates
    // do not approach the limits monotonically, and stopping on a bad one (5 iterations, 10 m/s)
    // set the flag flying apart through the velocity update.
    if (iteration == 0 || excess < result.excess) {
      result.excess = excess;
      g.best.assign(X, X + 3 * n);
    }
    g.rhs.resize(n, 3);
    for (int i = 0; i < n; ++i) g.rhs.row(i) = (pinned_[i] ? g.pin_weight : mass_[i]) * g.anchor.row(i);
    for (size_t f = 0; f < faces_.size(); ++f) {
      const Face& face = faces_[f];
      Eigen::Matrix<double, 3, 2>& u = g.duals[f];
      FaceProjection q;  // F + u, projected: z
      for (int r = 0; r < 3; ++r) {
        q.Fu[r] = shapes[f].Fu[r] + u(r, 0);
        q.Fv[r] = shapes[f].Fv[r] + u(r, 1);
      }
      Eigen::Matrix<double, 3, 2> z;
      if (ProjectShape(limits, &q)) {
        for (int r = 0; r < 3; ++r) {
          z(r, 0) = q.Fu[r] * q.m00 + q.Fv[r] * q.m01;
          z(r, 1) = q.Fu[r] * q.m01 + q.Fv[r] * q.m11;
        }
      } else {
        for (int r = 0; r < 3; ++r) {
          z(r, 0) = q.Fu[r];
          z(r, 1) = q.Fv[r];
        }
      }
      z_change = std::max(z_change, (z - g.projections[f]).cwiseAbs().maxCoeff());
      g.projections[f] = z;
      for (int r = 0; r < 3; ++r) {
        u(r, 0) += shapes[f].Fu[r] - z(r, 0);
        u(r, 1) += shapes[f].Fv[r] - z(r, 1);
      }
      // Normal equations' right side: c_f B_f^T (z - u)^T.
      const Eigen::Matrix3d contribution = face_weight_[f] * g.B[f].transpose() * (z - u).transpose();
      for (int a = 0; a < 3; ++a) g.rhs.row(face.v[a]) += contribution.row(a);
    }
    g.solved = g.solver.solve(g.rhs);
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) X[3 * i + c] = pinned_[i] ? g.anchor(i, c) : g.solved(i, c);
  }
  if (!result.converged) {
    // The last solve's positions were not checked: better only if within tolerance after all.
    const Standing last = measure();
    if (last.violated == 0) {
      result.converged = true;
      result.excess = last.excess;
    } else if (last.excess < result.excess) {
      result.excess = last.excess;
    } else {
      std::copy(g.best.begin(), g.best.end(), X);
    }
  }
  return result;
}

StrainLimitResult StrainLimiter::Project(const StrainLimitSettings& settings, double dt,
                                         Eigen::MatrixX3d* xp, Eigen::MatrixX3d* vp) {
  Eigen::MatrixX3d& x = *xp;
  const int n = static_cast<int>(x.rows());
  // A non-finite position is refused before anything moves: the global step's solve would spread
  // it to every vertex of the sheet (and a sweep would skip its faces without a word).
  for (int i = 0; i < n; ++i)
    if (!x.row(i).allFinite())
      throw std::invalid_argument("strain limiter: vertex " + std::to_string(i) +
                                  " has a non-finite position; expected finite positions [m]");
  // Work on an interleaved copy (x, y, z of a vertex adjacent in memory).
  work_.resize(3 * n);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) work_[3 * i + c] = x(i, c);
  const StrainLimitResult result =
      settings.method == StrainLimitMethod::kGlobal ? LocalGlobal(settings) : Sweep(settings);
  const double* X = work_.data();
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
