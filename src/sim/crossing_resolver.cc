#include "sim/crossing_resolver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#ifdef __SSE2__
#include <emmintrin.h>
#endif

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
  // Owners (see FindCandidates): the lowest-indexed face holding the vertex or edge.
  const int nf = static_cast<int>(F_.rows());
  const int nv = nf > 0 ? F_.maxCoeff() + 1 : 0;
  std::vector<int> vertex_owner(nv, -1), edge_owner(edges_.size(), -1);
  for (int f = nf - 1; f >= 0; --f)
    for (int k = 0; k < 3; ++k) {
      vertex_owner[F_(f, k)] = f;
      const int a = F_(f, k), b = F_(f, (k + 1) % 3);
      const auto it = std::lower_bound(edges_.begin(), edges_.end(), std::make_pair(std::min(a, b), std::max(a, b)));
      edge_owner[it - edges_.begin()] = f;
    }
  // Per face, its owned vertices and edges (CSR, ascending).
  auto group = [nf](const std::vector<int>& owner, std::vector<int>* start, std::vector<int>* items) {
    start->assign(nf + 1, 0);
    for (int o : owner)
      if (o >= 0) ++(*start)[o + 1];
    for (int f = 0; f < nf; ++f) (*start)[f + 1] += (*start)[f];
    items->assign((*start)[nf], 0);
    std::vector<int> fill(start->begin(), start->end() - 1);
    for (int i = 0; i < static_cast<int>(owner.size()); ++i)
      if (owner[i] >= 0) (*items)[fill[owner[i]]++] = i;
  };
  group(vertex_owner, &owned_start_, &owned_vertices_);
  group(edge_owner, &owned_edge_start_, &owned_edges_);
}

void CrossingResolver::OverlappingPairs(double gap) {
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
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      lo_cell_[i][a] = index(boxes_[i].min()[a], a);
      hi_cell_[i][a] = index(boxes_[i].max()[a] + gap, a);
    }
    for (int x = lo_cell_[i][0]; x <= hi_cell_[i][0]; ++x)
      for (int y = lo_cell_[i][1]; y <= hi_cell_[i][1]; ++y)
        for (int z = lo_cell_[i][2]; z <= hi_cell_[i][2]; ++z) ++cell_start_[(x * dims[1] + y) * dims[2] + z + 1];
  }
  for (int c = 0; c < num_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_entries_.resize(cell_start_[num_cells]);
  cell_fill_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = 0; i < n; ++i) {
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
  // low corner of the two cell ranges' intersection (along each axis, the query's or the entry's low
  // cell, whichever is higher). Only occupied cells are visited.
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const double lo[3] = {boxes_[i].min().x(), boxes_[i].min().y(), boxes_[i].min().z()};
    const double hi[3] = {boxes_[i].max().x() + gap, boxes_[i].max().y() + gap, boxes_[i].max().z() + gap};
    const int cx = lo_cell_[i][0], cy = lo_cell_[i][1], cz = lo_cell_[i][2];
#ifdef __SSE2__
    const __m128d lo01 = _mm_loadu_pd(lo), hi01 = _mm_loadu_pd(hi);
#endif
    for (int x = lo_cell_[i][0]; x <= hi_cell_[i][0]; ++x)
      for (int y = lo_cell_[i][1]; y <= hi_cell_[i][1]; ++y)
        for (int z = lo_cell_[i][2]; z <= hi_cell_[i][2]; ++z) {
          const int c = (x * dims[1] + y) * dims[2] + z;
          // At the query's own low cell along an axis, any entry owns the pair along it.
          const bool own_x = x == cx, own_y = y == cy, own_z = z == cz;
          // Branch-free: every entry is written, and kept only if it passes (the tests are
          // close to random, so branches would mostly mispredict).
          const int begin = cell_start_[c], end = cell_start_[c + 1];
          if (overlaps_.size() < static_cast<size_t>(count + end - begin)) overlaps_.resize(2 * (count + end - begin));
          std::pair<int, int>* out = overlaps_.data();
          // Entries ascend by index: from the top down, stop at the first one not above i.
          for (int p = end - 1; p >= begin; --p) {
            const Entry& e = cell_entries_[p];
            if (e.id <= i) break;
            // Ownership: max(query low cell, entry low cell) == this cell along every axis (the
            // cell is in both ranges, so it is at least both low cells).
            const bool owned = (own_x | (e.x == x)) & (own_y | (e.y == y)) & (own_z | (e.z == z));
#ifdef __SSE2__
            const __m128d overlap01 = _mm_and_pd(_mm_cmple_pd(_mm_loadu_pd(e.lo), hi01),
                                                 _mm_cmple_pd(lo01, _mm_loadu_pd(e.hi)));
            const bool keep = owned & (_mm_movemask_pd(overlap01) == 3) & (e.lo[2] <= hi[2]) & (lo[2] <= e.hi[2]);
#else
            const bool keep = owned & (e.lo[0] <= hi[0]) & (lo[0] <= e.hi[0]) & (e.lo[1] <= hi[1]) &
                              (lo[1] <= e.hi[1]) & (e.lo[2] <= hi[2]) & (lo[2] <= e.hi[2]);
#endif
            out[count] = {i, e.id};
            count += keep;
          }
        }
  }
  overlaps_.resize(count);
}

// One broad phase for both kinds of pairs, over the faces' swept boxes only: each vertex and
// each edge is owned by one face that contains it (whose swept box contains its own), so a
// vertex-face or edge-edge pair whose swept boxes overlap within reach lies in a face pair whose
// boxes overlap, and is found once, from the pair of its owners. This replaces two grid passes
// (faces against vertices, edges against edges) that mostly reported neighbours in the sheet.
void CrossingResolver::FindCandidates(const Eigen::MatrixX3d& X0, const Eigen::MatrixX3d& X1, double reach) {
  candidates_.clear();
  edge_candidates_.clear();
  const int nf = static_cast<int>(F_.rows()), nv = static_cast<int>(X1.rows());
  const int ne = static_cast<int>(edges_.size());
  vertex_boxes_.resize(nv);
  for (int v = 0; v < nv; ++v) {
    vertex_boxes_[v].setEmpty();
    vertex_boxes_[v].extend(X0.row(v).transpose());
    vertex_boxes_[v].extend(X1.row(v).transpose());
  }
  edge_boxes_.resize(ne);
  for (int e = 0; e < ne; ++e) edge_boxes_[e] = vertex_boxes_[edges_[e].first].merged(vertex_boxes_[edges_[e].second]);
  boxes_.resize(nf);
  for (int f = 0; f < nf; ++f)
    boxes_[f] = vertex_boxes_[F_(f, 0)].merged(vertex_boxes_[F_(f, 1)]).merged(vertex_boxes_[F_(f, 2)]);
  OverlappingPairs(reach);
  // Boxes overlap within reach (the grid's test, so the pairs are those of a direct search).
  auto near = [reach](const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
    return (a.min().array() <= b.max().array() + reach).all() && (b.min().array() <= a.max().array() + reach).all();
  };
  auto incident = [this](int v, int f) { return F_(f, 0) == v || F_(f, 1) == v || F_(f, 2) == v; };
  auto vertex_face = [&](int owner, int f) {
    for (int k = owned_start_[owner]; k < owned_start_[owner + 1]; ++k) {
      const int v = owned_vertices_[k];
      if (!incident(v, f) && near(vertex_boxes_[v], boxes_[f])) candidates_.push_back({v, f});
    }
  };
  for (const auto& [p, q] : overlaps_) {
    vertex_face(p, q);
    vertex_face(q, p);
    for (int a = owned_edge_start_[p]; a < owned_edge_start_[p + 1]; ++a)
      for (int b = owned_edge_start_[q]; b < owned_edge_start_[q + 1]; ++b) {
        const int i = owned_edges_[a], j = owned_edges_[b];
        const auto [ea, eb] = edges_[i];
        const auto [ec, ed] = edges_[j];
        if (ec == ea || ec == eb || ed == ea || ed == eb || !near(edge_boxes_[i], edge_boxes_[j])) continue;
        edge_candidates_.emplace_back(std::min(i, j), std::max(i, j));
      }
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
  for (const auto& [vertex, face] : candidates_) {
    const int id[4] = {vertex, F_(face, 0), F_(face, 1), F_(face, 2)};
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

int CrossingResolver::Resolve(const Eigen::MatrixX3d& X0, double gap, double reach, int max_sweeps,
                              Eigen::MatrixX3d* X, Eigen::MatrixX3d* V) {
  candidates_.clear();
  edge_candidates_.clear();
  if (!X->allFinite()) return 0;  // exploded: the simulator reports it
  FindCandidates(X0, *X, std::max(gap, reach));
  int corrections = 0;
  for (int sweep = 0; sweep < max_sweeps; ++sweep) {
    const int n = SweepVertexFace(X0, gap, X, V) + SweepEdgeEdge(X0, gap, X, V);
    corrections += n;
    if (n == 0) break;
  }
  return corrections;
}

}  // namespace clothwind::sim
