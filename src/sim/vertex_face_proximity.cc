#include "sim/vertex_face_proximity.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace clothwind::sim {
namespace {

// Exact key for cells within +-2^20 per axis (beyond that keys alias, which only adds candidates
// that the exact test then rejects).
std::uint64_t CellKey(std::int64_t i, std::int64_t j, std::int64_t k) {
  constexpr std::int64_t kOffset = 1 << 20;
  auto wrap = [](std::int64_t a) { return static_cast<std::uint64_t>((a + kOffset) & ((1 << 21) - 1)); };
  return (wrap(i) << 42) | (wrap(j) << 21) | wrap(k);
}

std::uint64_t Mix(std::uint64_t key) {
  key ^= key >> 33;
  key *= 0xff51afd7ed558ccdULL;
  key ^= key >> 33;
  return key;
}

// Cell index of coordinate c for 1/cell = inv; callers pass finite c of moderate size.
std::int64_t CellIndex(double c, double inv) { return static_cast<std::int64_t>(std::floor(c * inv)); }

// A face whose bounding box spans more cells than this along an axis is skipped. A face of a
// simulated cloth spans ~2-4 cells (the cell is about its edge length); thousands mean the state
// has exploded (or holds inf/NaN, for which floor() cast to an integer is undefined). Looping
// over such a box would take practically forever (cells^3), turning a blow-up into a hang,
// while its pairs would be meaningless anyway: the simulator reports the exploded state itself.
constexpr double kMaxCellsPerAxis = 32;

// Vertices and faces beyond +-kFar cells (or non-finite) are left out: converting their cell
// coordinate to an integer would overflow.
constexpr double kFar = 1e15;

// Whether a face's grown box [lo, hi] can be put in a grid of cells 1/inv wide: finite, at most
// kMaxCellsPerAxis cells across, within kFar cells of the origin. An exploded or non-finite face
// is not, and both Update and UpdateFromCandidates skip it.
bool FaceBoxUsable(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double inv) {
  return lo.allFinite() && hi.allFinite() && (hi - lo).maxCoeff() * inv <= kMaxCellsPerAxis &&
         lo.cwiseAbs().maxCoeff() * inv < kFar && hi.cwiseAbs().maxCoeff() * inv < kFar;
}

// The exact test shared by Update and UpdateFromCandidates: is p within thickness of the plane of
// face (a, b, c) with unit normal n (N = (b - a) x (c - a), nn = |N|^2), projecting inside the
// face, and inside the face's box grown by thickness (lo, hi)? Sets *side (+1: on n's side).
bool Near(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
          const Eigen::Vector3d& n, const Eigen::Vector3d& N, double nn, const Eigen::Vector3d& lo,
          const Eigen::Vector3d& hi, double thickness, double* side) {
  if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) return false;
  const Eigen::Vector3d ap = p - a;
  const double d = n.dot(ap);
  if (std::abs(d) >= thickness) return false;
  const double wb = ap.cross(c - a).dot(N) / nn;
  const double wc = (b - a).cross(ap).dot(N) / nn;
  if (wb < 0 || wc < 0 || wb + wc > 1) return false;
  *side = d >= 0 ? 1.0 : -1.0;
  return true;
}

}  // namespace

VertexFaceProximity::VertexFaceProximity(const Eigen::MatrixX3i& F, int num_vertices, double cell_size)
    : F_(F), num_vertices_(num_vertices), cell_size_(cell_size) {
  size_t buckets = 16;
  while (buckets < 2 * static_cast<size_t>(num_vertices)) buckets *= 2;
  bucket_head_.assign(buckets, -1);
  next_.assign(num_vertices, -1);
  key_.assign(num_vertices, 0);
}

void VertexFaceProximity::Update(const Eigen::MatrixX3d& X, double thickness) {
  pairs_.clear();
  if (!(thickness > 0) || F_.rows() == 0) return;
  const double cell = std::max(cell_size_, 2 * thickness);
  const double inv = 1.0 / cell;
  const std::uint64_t mask = bucket_head_.size() - 1;
  std::fill(bucket_head_.begin(), bucket_head_.end(), -1);
  // Insert in reverse so each bucket lists vertices in increasing order.
  // Vertices beyond +-kFar cells (or non-finite) are left out of the grid: converting their
  // cell coordinate to an integer would overflow, and no face they could be near is searched.
  for (int i = num_vertices_ - 1; i >= 0; --i) {
    const Eigen::Vector3d c = X.row(i).transpose() * inv;
    if (!c.allFinite() || !(c.cwiseAbs().maxCoeff() < kFar)) {
      next_[i] = -1;
      key_[i] = ~std::uint64_t{0};
      continue;
    }
    key_[i] = CellKey(CellIndex(X(i, 0), inv), CellIndex(X(i, 1), inv), CellIndex(X(i, 2), inv));
    int& head = bucket_head_[Mix(key_[i]) & mask];
    next_[i] = head;
    head = i;
  }
  for (int f = 0; f < F_.rows(); ++f) {
    const int ia = F_(f, 0), ib = F_(f, 1), ic = F_(f, 2);
    const Eigen::Vector3d a = X.row(ia), b = X.row(ib), c = X.row(ic);
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c).array() - thickness;
    const Eigen::Vector3d hi = a.cwiseMax(b).cwiseMax(c).array() + thickness;
    if (!FaceBoxUsable(lo, hi, inv)) continue;  // exploded or non-finite face (see kMaxCellsPerAxis)
    const Eigen::Vector3d N = (b - a).cross(c - a);
    const double nn = N.squaredNorm();
    if (!(nn > 0)) continue;
    const Eigen::Vector3d n = N / std::sqrt(nn);
    const auto i0 = CellIndex(lo.x(), inv), i1 = CellIndex(hi.x(), inv);
    const auto j0 = CellIndex(lo.y(), inv), j1 = CellIndex(hi.y(), inv);
    const auto k0 = CellIndex(lo.z(), inv), k1 = CellIndex(hi.z(), inv);
    found_.clear();
    for (auto i = i0; i <= i1; ++i)
      for (auto j = j0; j <= j1; ++j)
        for (auto k = k0; k <= k1; ++k) {
          const std::uint64_t key = CellKey(i, j, k);
          for (int vi = bucket_head_[Mix(key) & mask]; vi >= 0; vi = next_[vi]) {
            if (key_[vi] != key || vi == ia || vi == ib || vi == ic) continue;
            double side;
            if (!Near(X.row(vi).transpose(), a, b, c, n, N, nn, lo, hi, thickness, &side)) continue;
            found_.push_back(vi);
          }
        }
    if (found_.empty()) continue;
    std::sort(found_.begin(), found_.end());
    found_.erase(std::unique(found_.begin(), found_.end()), found_.end());
    for (int vi : found_) {
      const double d = n.dot(X.row(vi).transpose() - a);
      pairs_.push_back({vi, f, d >= 0 ? 1.0 : -1.0});
    }
  }
}

void VertexFaceProximity::UpdateFromCandidates(const Eigen::MatrixX3d& X, double thickness,
                                               const std::vector<std::pair<int, int>>& candidates) {
  pairs_.clear();
  scratch_.clear();
  if (!(thickness > 0) || F_.rows() == 0) return;
  const double inv = 1.0 / std::max(cell_size_, 2 * thickness);
  for (const auto& [vi, f] : candidates) {
    const int ia = F_(f, 0), ib = F_(f, 1), ic = F_(f, 2);
    if (vi == ia || vi == ib || vi == ic) continue;
    const Eigen::Vector3d a = X.row(ia), b = X.row(ib), c = X.row(ic);
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c).array() - thickness;
    const Eigen::Vector3d hi = a.cwiseMax(b).cwiseMax(c).array() + thickness;
    if (!FaceBoxUsable(lo, hi, inv)) continue;  // the faces Update skips are skipped here too
    const Eigen::Vector3d p = X.row(vi).transpose();
    if (!(p.cwiseAbs().maxCoeff() * inv < kFar)) continue;  // also false for non-finite: left out, as in Update
    const Eigen::Vector3d N = (b - a).cross(c - a);
    const double nn = N.squaredNorm();
    if (!(nn > 0)) continue;
    const Eigen::Vector3d n = N / std::sqrt(nn);
    double side;
    if (Near(p, a, b, c, n, N, nn, lo, hi, thickness, &side)) scratch_.push_back({vi, f, side});
  }
  // Update's order: by face, then vertex.
  std::sort(scratch_.begin(), scratch_.end(),
            [](const Pair& p, const Pair& q) { return p.face != q.face ? p.face < q.face : p.vertex < q.vertex; });
  pairs_.assign(scratch_.begin(), scratch_.end());
}

}  // namespace clothwind::sim
