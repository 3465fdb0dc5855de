#include "sim/crossing_resolver.h"

#include <algorithm>
#include <cmath>

namespace clothwind::sim {
namespace {

// A crossing point this far outside a face (in barycentric units) still counts: a vertex that
// crosses exactly at a shared edge must be caught by one of the two faces despite rounding.
constexpr double kInsideTolerance = 1e-2;

}  // namespace

CrossingResolver::CrossingResolver(const Eigen::MatrixX3i& F, const Eigen::VectorXd& inverse_mass)
    : F_(F), inverse_mass_(inverse_mass) {
  for (int f = 0; f < F_.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F_(f, k), b = F_(f, (k + 1) % 3);
      edges_.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges_.begin(), edges_.end());
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
}

// Sweep and prune: the boxes (grown by gap) sorted by their low end along the axis over which
// the positions spread most; each box is paired with the following ones that start before it
// ends and overlap it along the other two axes. Deterministic (ties broken by index).
void CrossingResolver::SweepAndPrune(const Eigen::MatrixX3d& X1, double gap, std::vector<int>* order) {
  overlaps_.clear();
  const int n = static_cast<int>(boxes_.size());
  for (const Eigen::AlignedBox3d& b : boxes_)
    if (!b.min().allFinite() || !b.max().allFinite()) return;  // exploded: the simulator reports it
  const Eigen::Vector3d spread = X1.colwise().maxCoeff() - X1.colwise().minCoeff();
  int axis = 0;
  spread.maxCoeff(&axis);
  const int u = (axis + 1) % 3, w = (axis + 2) % 3;
  // Insertion sort from the previous step's order: nearly sorted already, so about linear.
  std::vector<int>& ord = *order;
  if (static_cast<int>(ord.size()) != n) {
    ord.resize(n);
    for (int i = 0; i < n; ++i) ord[i] = i;
  }
  auto less = [&](int a, int b) {
    const double la = boxes_[a].min()[axis], lb = boxes_[b].min()[axis];
    return la < lb || (la == lb && a < b);
  };
  for (int i = 1; i < n; ++i) {
    const int key = ord[i];
    int j = i - 1;
    while (j >= 0 && less(key, ord[j])) {
      ord[j + 1] = ord[j];
      --j;
    }
    ord[j + 1] = key;
  }
  // Contiguous copy in sorted order, grown by gap at the high ends, for the scan.
  sap_.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::AlignedBox3d& b = boxes_[ord[i]];
    sap_[i] = {b.min()[axis], b.max()[axis] + gap, b.min()[u], b.max()[u] + gap, b.min()[w], b.max()[w] + gap,
               ord[i]};
  }
  for (int i = 0; i < n; ++i) {
    const SapBox& a = sap_[i];
    for (int j = i + 1; j < n; ++j) {
      const SapBox& b = sap_[j];
      if (b.lo0 > a.hi0) break;
      if (b.lo1 > a.hi1 || a.lo1 > b.hi1 || b.lo2 > a.hi2 || a.lo2 > b.hi2) continue;
      overlaps_.emplace_back(std::min(a.id, b.id), std::max(a.id, b.id));
    }
  }
}

// Edge pairs (no shared vertex) whose swept boxes (start and end positions) overlap within gap.
void CrossingResolver::FindEdgeCandidates(const Eigen::MatrixX3d& X0, const Eigen::MatrixX3d& X1, double gap) {
  edge_candidates_.clear();
  const int ne = static_cast<int>(edges_.size());
  boxes_.resize(ne);
  for (int e = 0; e < ne; ++e) {
    boxes_[e].setEmpty();
    for (int v : {edges_[e].first, edges_[e].second}) {
      boxes_[e].extend(X0.row(v).transpose());
      boxes_[e].extend(X1.row(v).transpose());
    }
  }
  SweepAndPrune(X1, gap, &edge_order_);
  for (const auto& [i, j] : overlaps_) {
    const int a = edges_[i].first, b = edges_[i].second, c = edges_[j].first, d = edges_[j].second;
    if (c == a || c == b || d == a || d == b) continue;
    edge_candidates_.emplace_back(i, j);
  }
}

// Vertex-face pairs (vertex not of the face) whose swept boxes overlap within gap.
void CrossingResolver::FindCandidates(const Eigen::MatrixX3d& X0, const Eigen::MatrixX3d& X1, double gap) {
  candidates_.clear();
  const int nf = static_cast<int>(F_.rows()), nv = static_cast<int>(X1.rows());
  boxes_.resize(nf + nv);
  for (int f = 0; f < nf; ++f) {
    boxes_[f].setEmpty();
    for (int k = 0; k < 3; ++k) {
      boxes_[f].extend(X0.row(F_(f, k)).transpose());
      boxes_[f].extend(X1.row(F_(f, k)).transpose());
    }
  }
  for (int v = 0; v < nv; ++v) {
    boxes_[nf + v].setEmpty();
    boxes_[nf + v].extend(X0.row(v).transpose());
    boxes_[nf + v].extend(X1.row(v).transpose());
  }
  SweepAndPrune(X1, gap, &vertex_face_order_);
  for (const auto& [i, j] : overlaps_) {
    if ((i < nf) == (j < nf)) continue;  // face-face or vertex-vertex
    const int f = i, v = j - nf;  // i < j
    if (F_(f, 0) == v || F_(f, 1) == v || F_(f, 2) == v) continue;
    candidates_.push_back({v, f});
  }
}

bool CrossingResolver::Push(const int id[4], const double coef[4], const Eigen::Vector3d& n, double gap,
                            Eigen::MatrixX3d* X, Eigen::MatrixX3d* V) const {
  double denom = 0, c = 0, vn = 0;
  for (int k = 0; k < 4; ++k) {
    denom += coef[k] * coef[k] * inverse_mass_[id[k]];
    c += coef[k] * n.dot(X->row(id[k]).transpose());
    vn += coef[k] * n.dot(V->row(id[k]).transpose());
  }
  if (!(denom > 0) || c >= gap) return false;
  const double lambda = (gap - c) / denom;
  const double mu = vn < 0 ? -vn / denom : 0.0;
  for (int k = 0; k < 4; ++k) {
    const double im = inverse_mass_[id[k]];
    X->row(id[k]) += (lambda * im * coef[k]) * n.transpose();
    V->row(id[k]) += (mu * im * coef[k]) * n.transpose();
  }
  return true;
}

int CrossingResolver::SweepVertexFace(const Eigen::MatrixX3d& X0, double gap, Eigen::MatrixX3d* X,
                                      Eigen::MatrixX3d* V) {
  const Eigen::MatrixX3d& X1 = *X;
  int corrections = 0;
  for (const Candidate& cand : candidates_) {
    const int id[4] = {cand.vertex, F_(cand.face, 0), F_(cand.face, 1), F_(cand.face, 2)};
    Eigen::Vector3d s[4], e[4];
    for (int k = 0; k < 4; ++k) {
      s[k] = X0.row(id[k]).transpose();
      e[k] = X1.row(id[k]).transpose();
    }
    const Eigen::Vector3d N0 = (s[2] - s[1]).cross(s[3] - s[1]);
    const Eigen::Vector3d N1 = (e[2] - e[1]).cross(e[3] - e[1]);
    const double n0 = N0.norm(), n1 = N1.norm();
    if (!(n0 > 0) || !(n1 > 0)) continue;
    const double d0 = N0.dot(s[0] - s[1]) / n0;
    const double d1 = N1.dot(e[0] - e[1]) / n1;
    if (d0 == 0 || ((d0 > 0) == (d1 > 0) && d1 != 0)) continue;  // same side: no crossing
    // Where the path crosses the face's plane (all four points moving linearly).
    const double t = d0 / (d0 - d1);
    Eigen::Vector3d m[4];
    for (int k = 0; k < 4; ++k) m[k] = s[k] + t * (e[k] - s[k]);
    const Eigen::Vector3d Nm = (m[2] - m[1]).cross(m[3] - m[1]);
    const double nnm = Nm.squaredNorm();
    if (!(nnm > 0)) continue;
    const Eigen::Vector3d ap = m[0] - m[1];
    double wb = ap.cross(m[3] - m[1]).dot(Nm) / nnm;
    double wc = (m[2] - m[1]).cross(ap).dot(Nm) / nnm;
    double wa = 1 - wb - wc;
    if (wa < -kInsideTolerance || wb < -kInsideTolerance || wc < -kInsideTolerance) continue;
    wa = std::max(wa, 0.0);
    wb = std::max(wb, 0.0);
    wc = std::max(wc, 0.0);
    const double wsum = wa + wb + wc;
    // Constraint side n . (p - sum w_i x_i) >= gap, n the end normal.
    const Eigen::Vector3d n = (d0 > 0 ? 1.0 : -1.0) * N1 / n1;
    const double coef[4] = {1.0, -wa / wsum, -wb / wsum, -wc / wsum};
    corrections += Push(id, coef, n, gap, X, V);
  }
  return corrections;
}

// Parameters (s on p0q0, u on p1q1, both clamped to [0, 1]) of the closest points of two segments.
static void ClosestSegmentParameters(const Eigen::Vector3d& p0, const Eigen::Vector3d& q0, const Eigen::Vector3d& p1,
                              const Eigen::Vector3d& q1, double* s, double* u) {
  const Eigen::Vector3d d0 = q0 - p0, d1 = q1 - p1, r = p0 - p1;
  const double a = d0.squaredNorm(), e = d1.squaredNorm(), f = d1.dot(r), c = d0.dot(r), b = d0.dot(d1);
  const double den = a * e - b * b;
  double ss = den > 1e-30 ? std::clamp((b * f - c * e) / den, 0.0, 1.0) : 0.0;
  double uu = e > 0 ? (b * ss + f) / e : 0.0;
  if (uu < 0 || uu > 1) {
    uu = std::clamp(uu, 0.0, 1.0);
    ss = a > 0 ? std::clamp((b * uu - c) / a, 0.0, 1.0) : 0.0;
  }
  *s = ss;
  *u = uu;
}

int CrossingResolver::SweepEdgeEdge(const Eigen::MatrixX3d& X0, double gap, Eigen::MatrixX3d* X,
                                    Eigen::MatrixX3d* V) {
  const Eigen::MatrixX3d& X1 = *X;
  int corrections = 0;
  for (const auto& [ei, ej] : edge_candidates_) {
    const int id[4] = {edges_[ei].first, edges_[ei].second, edges_[ej].first, edges_[ej].second};
    Eigen::Vector3d s[4], e[4];
    for (int k = 0; k < 4; ++k) {
      s[k] = X0.row(id[k]).transpose();
      e[k] = X1.row(id[k]).transpose();
    }
    // Signed volume of the tetrahedron: changes sign when the edges' lines pass each other.
    const double v0 = (s[1] - s[0]).cross(s[3] - s[2]).dot(s[2] - s[0]);
    const double v1 = (e[1] - e[0]).cross(e[3] - e[2]).dot(e[2] - e[0]);
    if (v0 == 0 || ((v0 > 0) == (v1 > 0) && v1 != 0)) continue;
    const double t = v0 / (v0 - v1);
    Eigen::Vector3d m[4];
    for (int k = 0; k < 4; ++k) m[k] = s[k] + t * (e[k] - s[k]);
    double a, b;
    ClosestSegmentParameters(m[0], m[1], m[2], m[3], &a, &b);
    // The lines met within both segments (closest points close at that moment)?
    const Eigen::Vector3d pa = m[0] + a * (m[1] - m[0]), pb = m[2] + b * (m[3] - m[2]);
    const double scale = std::max((m[1] - m[0]).norm(), (m[3] - m[2]).norm());
    if ((pa - pb).norm() > 1e-2 * scale + gap) continue;
    if (a <= 0 || a >= 1 || b <= 0 || b >= 1) continue;  // at an end: the vertex-face test's case
    const Eigen::Vector3d N1 = (e[1] - e[0]).cross(e[3] - e[2]);
    const double n1 = N1.norm();
    if (!(n1 > 1e-12 * (e[1] - e[0]).squaredNorm())) continue;  // parallel at the end
    // Constraint side n . (x_b - x_a) >= gap, side from the volume's sign at the start.
    const Eigen::Vector3d n = (v0 > 0 ? 1.0 : -1.0) * N1 / n1;
    const double coef[4] = {-(1 - a), -a, 1 - b, b};
    corrections += Push(id, coef, n, gap, X, V);
  }
  return corrections;
}

int CrossingResolver::Resolve(const Eigen::MatrixX3d& X0, double gap, int max_sweeps, Eigen::MatrixX3d* X,
                              Eigen::MatrixX3d* V) {
  if (!X->allFinite()) return 0;  // exploded: the simulator reports it
  FindCandidates(X0, *X, gap);
  FindEdgeCandidates(X0, *X, gap);
  int corrections = 0;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    const int n = SweepVertexFace(X0, gap, X, V) + SweepEdgeEdge(X0, gap, X, V);
    corrections += n;
    if (n == 0) break;
  }
  return corrections;
}

}  // namespace clothwind::sim
