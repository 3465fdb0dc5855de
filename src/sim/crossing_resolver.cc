#include "sim/crossing_resolver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

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
void CrossingResolver::OverlappingPairs(double gap, int num_queries) {
  overlaps_.clear();
  const int n = static_cast<int>(boxes_.size());
  if (n == 0) return;
  Eigen::AlignedBox3d all;
  all.setEmpty();
  Eigen::Vector3d mean_size = Eigen::Vector3d::Zero();
  for (const Eigen::AlignedBox3d& b : boxes_) {
    if (!b.min().allFinite() || !b.max().allFinite()) return;  // exploded: the simulator reports it
    all.extend(b);
    mean_size += b.sizes();
  }
  // Cells about the mean box size, at most kMaxCells in all (an exploded state gets big cells).
  constexpr double kMaxCells = 1 << 16;
  const Eigen::Vector3d extent = all.sizes().array() + gap;
  double cell = std::max(mean_size.maxCoeff() / n + gap, 1e-9);
  while ((extent / cell).array().floor().matrix().prod() + 1 > kMaxCells ||
         ((extent / cell).array() + 1).prod() > kMaxCells)
    cell *= 2;
  const double inv = 1.0 / cell;
  Eigen::Array3i dims = ((extent * inv).array().floor() + 1).cast<int>();
  const Eigen::Vector3d origin = all.min();
  auto index = [&](double c, int axis) {
    // c >= origin, so truncation is floor (std::floor is a library call without SSE4.1).
    return std::min(static_cast<int>((c - origin[axis]) * inv), dims[axis] - 1);
  };
  lo_cell_.resize(n);
  hi_cell_.resize(n);
  const int num_cells = dims.prod();

  cell_start_.assign(num_cells + 1, 0);
  const int first_inserted = num_queries;  // 0: all boxes against each other
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo_cell_[i][a] = index(boxes_[i].min()[a], a);
      hi_cell_[i][a] = index(boxes_[i].max()[a] + gap, a);
    }
    if (i < first_inserted) continue;
    for (int x = lo_cell_[i][0]; x <= hi_cell_[i][0]; ++x)
      for (int y = lo_cell_[i][1]; y <= hi_cell_[i][1]; ++y)
        for (int z = lo_cell_[i][2]; z <= hi_cell_[i][2]; ++z) ++cell_start_[(x * dims[1] + y) * dims[2] + z + 1];
  }
  for (int c = 0; c < num_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_entries_.resize(cell_start_[num_cells]);
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = first_inserted; i < n; ++i) {
    const Eigen::AlignedBox3d& b = boxes_[i];
    const Entry entry{{b.min().x(), b.min().y(), b.min().z()},
                      {b.max().x() + gap, b.max().y() + gap, b.max().z() + gap},
                      i, lo_cell_[i][0], lo_cell_[i][1], lo_cell_[i][2]};
    for (int x = lo_cell_[i][0]; x <= hi_cell_[i][0]; ++x)
      for (int y = lo_cell_[i][1]; y <= hi_cell_[i][1]; ++y)
        for (int z = lo_cell_[i][2]; z <= hi_cell_[i][2]; ++z)
          cell_entries_[cell_fill_[(x * dims[1] + y) * dims[2] + z]++] = entry;
  }
  // Each overlapping pair is reported once: from its lower-indexed box (the query), in the cell holding the
  // low corner of the two cell ranges' intersection. Only occupied cells are visited.
  const int num_query = num_queries > 0 ? num_queries : n;
  int count = 0;
  for (int i = 0; i < num_query; ++i) {
    const double lo[3] = {boxes_[i].min().x(), boxes_[i].min().y(), boxes_[i].min().z()};
    const double hi[3] = {boxes_[i].max().x() + gap, boxes_[i].max().y() + gap, boxes_[i].max().z() + gap};
    const int cx = lo_cell_[i][0], cy = lo_cell_[i][1], cz = lo_cell_[i][2];
    for (int x = lo_cell_[i][0]; x <= hi_cell_[i][0]; ++x)
      for (int y = lo_cell_[i][1]; y <= hi_cell_[i][1]; ++y)
        for (int z = lo_cell_[i][2]; z <= hi_cell_[i][2]; ++z) {
          const int c = (x * dims[1] + y) * dims[2] + z;
          // Branch-free: every entry is written, and kept only if it passes (the tests are
          // close to random, so branches would mostly mispredict).
          const int begin = cell_start_[c], end = cell_start_[c + 1];
          if (overlaps_.size() < static_cast<size_t>(count + end - begin)) overlaps_.resize(2 * (count + end - begin));
          std::pair<int, int>* out = overlaps_.data();
          // Entries ascend by index: from the top down, stop at the first one not above i.
          for (int p = end - 1; p >= begin; --p) {
            const Entry& e = cell_entries_[p];
            if (e.id <= i) break;
            const bool keep = (std::max(cx, e.x) == x) & (std::max(cy, e.y) == y) &
                              (std::max(cz, e.z) == z) & (e.lo[0] <= hi[0]) & (lo[0] <= e.hi[0]) &
                              (e.lo[1] <= hi[1]) & (lo[1] <= e.hi[1]) & (e.lo[2] <= hi[2]) & (lo[2] <= e.hi[2]);
            out[count] = {i, e.id};
            count += keep;
          }
        }
  }
  overlaps_.resize(count);
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
  OverlappingPairs(gap, 0);
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
  OverlappingPairs(gap, nf);  // faces against vertices
  for (const auto& [i, j] : overlaps_) {
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
