#include "sim/crossing_resolver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#ifdef __SSE__
#include <xmmintrin.h>
#endif

namespace clothwind::sim {
namespace {

// A crossing point this far outside a face (in barycentric units) still counts: a vertex that
// crosses exactly at a shared edge must be caught by one of the two faces despite rounding.
constexpr double kInsideTolerance = 1e-2;

}  // namespace

CrossingResolver::CrossingResolver(const Eigen::MatrixX3i& F, const Eigen::VectorXd& inverse_mass)
    : inverse_mass_(inverse_mass) {
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      edges_.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges_.begin(), edges_.end());
  edges_.erase(std::unique(edges_.begin(), edges_.end()), edges_.end());
  // Owners (see FindCandidates): the lowest-indexed face holding the vertex or edge.
  const int nf = static_cast<int>(F.rows());
  const int nv = nf > 0 ? F.maxCoeff() + 1 : 0;
  std::vector<int> vertex_owner(nv, -1), edge_owner(edges_.size(), -1);
  for (int f = nf - 1; f >= 0; --f)
    for (int k = 0; k < 3; ++k) {
      vertex_owner[F(f, k)] = f;
      const int a = F(f, k), b = F(f, (k + 1) % 3);
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
  faces_.resize(nf);
  for (int f = 0; f < nf; ++f) faces_[f] = {F(f, 0), F(f, 1), F(f, 2)};

  // Faces sharing a vertex (p < q) and their owned-primitive pairs, as FindCandidates' grid
  // would expand them (same exclusions), once for the fixed mesh.
  std::vector<std::vector<int>> faces_of_vertex(nv);
  for (int f = 0; f < nf; ++f)
    for (int v : faces_[f]) faces_of_vertex[v].push_back(f);
  std::vector<int> neighbours;
  for (int p = 0; p < nf; ++p) {
    neighbours.clear();
    for (int v : faces_[p])
      for (int q : faces_of_vertex[v])
        if (q > p) neighbours.push_back(q);
    std::sort(neighbours.begin(), neighbours.end());
    neighbours.erase(std::unique(neighbours.begin(), neighbours.end()), neighbours.end());
    for (int q : neighbours)
      ForEachOwnedPair(
          p, q, [this](int v, int f) { near_vertex_face_.emplace_back(v, f); },
          [this](int i, int j) { near_edge_edge_.emplace_back(i, j); });
  }
}

template <class VertexFace, class EdgeEdge>
void CrossingResolver::ForEachOwnedPair(int p, int q, VertexFace vertex_face, EdgeEdge edge_edge) const {
  auto owned_vertices_against = [&](int owner, int f) {
    const std::array<int, 3>& face = faces_[f];
    for (int k = owned_start_[owner]; k < owned_start_[owner + 1]; ++k) {
      const int v = owned_vertices_[k];
      if (face[0] != v && face[1] != v && face[2] != v) vertex_face(v, f);
    }
  };
  owned_vertices_against(p, q);
  owned_vertices_against(q, p);
  for (int a = owned_edge_start_[p]; a < owned_edge_start_[p + 1]; ++a)
    for (int b = owned_edge_start_[q]; b < owned_edge_start_[q + 1]; ++b) {
      const int i = owned_edges_[a], j = owned_edges_[b];
      const auto [ea, eb] = edges_[i];
      const auto [ec, ed] = edges_[j];
      if (ec != ea && ec != eb && ed != ea && ed != eb) edge_edge(std::min(i, j), std::max(i, j));
    }
}

inline bool CrossingResolver::ShareVertex(int p, int q) const {
  const std::array<int, 3>& a = faces_[p];
  const std::array<int, 3>& b = faces_[q];
  bool share = false;
  for (int i = 0; i < 3; ++i) share |= (a[i] == b[0]) | (a[i] == b[1]) | (a[i] == b[2]);
  return share;
}

namespace {

// Boxes a and b overlap when grown by r (lane 3 of both is 0, so it always passes).
inline bool BoxesNear(const float a_lo[4], const float a_hi[4], const float b_lo[4], const float b_hi[4], float r) {
#ifdef __SSE__
  const __m128 rr = _mm_set1_ps(r);
  const __m128 m = _mm_and_ps(_mm_cmple_ps(_mm_load_ps(a_lo), _mm_add_ps(_mm_load_ps(b_hi), rr)),
                              _mm_cmple_ps(_mm_load_ps(b_lo), _mm_add_ps(_mm_load_ps(a_hi), rr)));
  return (_mm_movemask_ps(m) & 7) == 7;
#else
  bool near = true;
  for (int k = 0; k < 3; ++k) near &= (a_lo[k] <= b_hi[k] + r) & (b_lo[k] <= a_hi[k] + r);
  return near;
#endif
}

}  // namespace

// Sort and sweep along the axis over which the faces spread most: the faces stay nearly in order
// from one step to the next, so an insertion sort of the previous order costs little, and each
// face is tested against the faces after it whose intervals start within its own, four at a time.
void CrossingResolver::OverlappingFarPairs(float gap) {
  overlaps_.clear();
  const int n = static_cast<int>(face_boxes_.size());
  if (n == 0) return;
  float lo[3], hi[3];
  for (int k = 0; k < 3; ++k) {
    lo[k] = face_boxes_[0].lo[k];
    hi[k] = face_boxes_[0].hi[k];
  }
  for (const Box& b : face_boxes_)
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(b.lo[k]) || !std::isfinite(b.hi[k])) return;  // exploded: the simulator reports it
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
    }
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
  const int b_axis = (axis + 1) % 3, c_axis = (axis + 2) % 3;
  if (static_cast<int>(sweep_order_.size()) != n) {
    sweep_order_.resize(n);
    for (int i = 0; i < n; ++i) sweep_order_[i] = i;
  }
  // Insertion sort by (low end along the axis, index): linear when nearly sorted.
  auto key_less = [&](int a, int b) {
    const float ka = face_boxes_[a].lo[axis], kb = face_boxes_[b].lo[axis];
    return ka < kb || (ka == kb && a < b);
  };
  for (int i = 1; i < n; ++i) {
    const int f = sweep_order_[i];
    int j = i - 1;
    while (j >= 0 && key_less(f, sweep_order_[j])) {
      sweep_order_[j + 1] = sweep_order_[j];
      --j;
    }
    sweep_order_[j + 1] = f;
  }
  // Structure of arrays in sweep order, padded by 3 boxes that end every sweep (+inf).
  const int padded = n + 3;
  for (auto* a : {&sweep_a_lo_, &sweep_a_hi_, &sweep_b_lo_, &sweep_b_hi_, &sweep_c_lo_, &sweep_c_hi_})
    a->resize(padded);
  for (int i = 0; i < n; ++i) {
    const Box& b = face_boxes_[sweep_order_[i]];
    sweep_a_lo_[i] = b.lo[axis];
    sweep_a_hi_[i] = b.hi[axis] + gap;
    sweep_b_lo_[i] = b.lo[b_axis];
    sweep_b_hi_[i] = b.hi[b_axis] + gap;
    sweep_c_lo_[i] = b.lo[c_axis];
    sweep_c_hi_[i] = b.hi[c_axis] + gap;
  }
  constexpr float kInf = std::numeric_limits<float>::infinity();
  for (int i = n; i < padded; ++i) {
    sweep_a_lo_[i] = kInf;
    sweep_a_hi_[i] = sweep_b_lo_[i] = sweep_b_hi_[i] = sweep_c_lo_[i] = sweep_c_hi_[i] = 0.0f;
  }
  for (int i = 0; i < n; ++i) {
    const int fi = sweep_order_[i];
    const float a_hi = sweep_a_hi_[i], b_lo = sweep_b_lo_[i], b_hi = sweep_b_hi_[i], c_lo = sweep_c_lo_[i],
                c_hi = sweep_c_hi_[i];
    // Boxes j > i start at or after box i along the axis; they overlap it there while they start
    // before its (grown) high end. Across: both ways, each high end grown by gap.
    for (int j = i + 1; j < n; j += 4) {
#ifdef __SSE__
      const __m128 starts = _mm_cmple_ps(_mm_loadu_ps(&sweep_a_lo_[j]), _mm_set1_ps(a_hi));
      if (_mm_movemask_ps(starts) == 0) break;
      const __m128 across = _mm_and_ps(
          _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(&sweep_b_lo_[j]), _mm_set1_ps(b_hi)),
                     _mm_cmple_ps(_mm_set1_ps(b_lo), _mm_loadu_ps(&sweep_b_hi_[j]))),
          _mm_and_ps(_mm_cmple_ps(_mm_loadu_ps(&sweep_c_lo_[j]), _mm_set1_ps(c_hi)),
                     _mm_cmple_ps(_mm_set1_ps(c_lo), _mm_loadu_ps(&sweep_c_hi_[j]))));
      int mask = _mm_movemask_ps(_mm_and_ps(starts, across));
#else
      int mask = 0;
      for (int l = 0; l < 4; ++l)
        mask |= ((sweep_a_lo_[j + l] <= a_hi) & (sweep_b_lo_[j + l] <= b_hi) & (b_lo <= sweep_b_hi_[j + l]) &
                 (sweep_c_lo_[j + l] <= c_hi) & (c_lo <= sweep_c_hi_[j + l]))
                << l;
      if (!(sweep_a_lo_[j] <= a_hi)) break;
#endif
      while (mask) {
        const int l = __builtin_ctz(mask);
        mask &= mask - 1;
        if (j + l >= n) break;
        const int fj = sweep_order_[j + l];
        // Faces sharing a vertex are the fixed near lists' (see the constructor).
        if (!ShareVertex(fi, fj)) overlaps_.emplace_back(std::min(fi, fj), std::max(fi, fj));
      }
    }
  }
  // The order is the sweep's: the same for the same states (deterministic), so no sort.
}

void CrossingResolver::ExpandFacePair(int p, int q, float reach) {
  ForEachOwnedPair(
      p, q,
      [&](int v, int f) {
        if (BoxesNear(vertex_boxes_[v].lo, vertex_boxes_[v].hi, face_boxes_[f].lo, face_boxes_[f].hi, reach))
          candidates_.emplace_back(v, f);
      },
      [&](int i, int j) {
        if (BoxesNear(edge_boxes_[i].lo, edge_boxes_[i].hi, edge_boxes_[j].lo, edge_boxes_[j].hi, reach))
          edge_candidates_.emplace_back(i, j);
      });
}

// Candidates come from the faces' swept boxes: each vertex and each edge is owned by one face that
// contains it (whose swept box contains its own), so a vertex-face or edge-edge pair whose swept
// boxes overlap within reach lies in a face pair whose boxes overlap, and is found once, from the
// pair of its owners. Owner pairs that share a vertex always overlap; their primitive pairs are
// fixed lists (near_vertex_face_, near_edge_edge_), tested box against box, and the sort and
// sweep only looks for the others: where the sheet comes back onto itself.
void CrossingResolver::FindCandidates(const Eigen::MatrixX3d& X0, const Eigen::MatrixX3d& X1, double reach) {
  candidates_.clear();
  edge_candidates_.clear();
  const int nf = static_cast<int>(faces_.size()), nv = static_cast<int>(X1.rows());
  const int ne = static_cast<int>(edges_.size());
  const float r = static_cast<float>(reach + kBoxPadding);
  vertex_boxes_.resize(nv);
  for (int v = 0; v < nv; ++v) {
    Box& b = vertex_boxes_[v];
    for (int k = 0; k < 3; ++k) {
      b.lo[k] = static_cast<float>(std::min(X0(v, k), X1(v, k)));
      b.hi[k] = static_cast<float>(std::max(X0(v, k), X1(v, k)));
    }
    b.lo[3] = b.hi[3] = 0.0f;
  }
  auto merge = [](const Box& a, const Box& b, Box* out) {
#ifdef __SSE__
    _mm_store_ps(out->lo, _mm_min_ps(_mm_load_ps(a.lo), _mm_load_ps(b.lo)));
    _mm_store_ps(out->hi, _mm_max_ps(_mm_load_ps(a.hi), _mm_load_ps(b.hi)));
#else
    for (int k = 0; k < 4; ++k) {
      out->lo[k] = std::min(a.lo[k], b.lo[k]);
      out->hi[k] = std::max(a.hi[k], b.hi[k]);
    }
#endif
  };
  edge_boxes_.resize(ne);
  for (int e = 0; e < ne; ++e) merge(vertex_boxes_[edges_[e].first], vertex_boxes_[edges_[e].second], &edge_boxes_[e]);
  face_boxes_.resize(nf);
  for (int f = 0; f < nf; ++f) {
    merge(vertex_boxes_[faces_[f][0]], vertex_boxes_[faces_[f][1]], &face_boxes_[f]);
    merge(face_boxes_[f], vertex_boxes_[faces_[f][2]], &face_boxes_[f]);
  }
  // Neighbours in the sheet: fixed lists (mostly rejected, so written branch-free).
  candidates_.resize(near_vertex_face_.size());
  int count = 0;
  for (const auto& [v, f] : near_vertex_face_) {
    candidates_[count] = {v, f};
    count += BoxesNear(vertex_boxes_[v].lo, vertex_boxes_[v].hi, face_boxes_[f].lo, face_boxes_[f].hi, r);
  }
  candidates_.resize(count);
  edge_candidates_.resize(near_edge_edge_.size());
  count = 0;
  for (const auto& [i, j] : near_edge_edge_) {
    edge_candidates_[count] = {i, j};
    count += BoxesNear(edge_boxes_[i].lo, edge_boxes_[i].hi, edge_boxes_[j].lo, edge_boxes_[j].hi, r);
  }
  edge_candidates_.resize(count);
  // Faces apart in the sheet whose boxes meet.
  OverlappingFarPairs(r);
  for (const auto& [p, q] : overlaps_) ExpandFacePair(p, q, r);
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
    const int id[4] = {vertex, faces_[face][0], faces_[face][1], faces_[face][2]};
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
