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
  for (int i = num_vertices_ - 1; i >= 0; --i) {
    key_[i] = CellKey(static_cast<std::int64_t>(std::floor(X(i, 0) * inv)),
                      static_cast<std::int64_t>(std::floor(X(i, 1) * inv)),
                      static_cast<std::int64_t>(std::floor(X(i, 2) * inv)));
    int& head = bucket_head_[Mix(key_[i]) & mask];
    next_[i] = head;
    head = i;
  }
  for (int f = 0; f < F_.rows(); ++f) {
    const int ia = F_(f, 0), ib = F_(f, 1), ic = F_(f, 2);
    const Eigen::Vector3d a = X.row(ia), b = X.row(ib), c = X.row(ic);
    const Eigen::Vector3d lo = a.cwiseMin(b).cwiseMin(c).array() - thickness;
    const Eigen::Vector3d hi = a.cwiseMax(b).cwiseMax(c).array() + thickness;
    const Eigen::Vector3d N = (b - a).cross(c - a);
    const double nn = N.squaredNorm();
    if (nn == 0) continue;
    const Eigen::Vector3d n = N / std::sqrt(nn);
    const auto i0 = static_cast<std::int64_t>(std::floor(lo.x() * inv)),
               i1 = static_cast<std::int64_t>(std::floor(hi.x() * inv));
    const auto j0 = static_cast<std::int64_t>(std::floor(lo.y() * inv)),
               j1 = static_cast<std::int64_t>(std::floor(hi.y() * inv));
    const auto k0 = static_cast<std::int64_t>(std::floor(lo.z() * inv)),
               k1 = static_cast<std::int64_t>(std::floor(hi.z() * inv));
    found_.clear();
    for (auto i = i0; i <= i1; ++i)
      for (auto j = j0; j <= j1; ++j)
        for (auto k = k0; k <= k1; ++k) {
          const std::uint64_t key = CellKey(i, j, k);
          for (int vi = bucket_head_[Mix(key) & mask]; vi >= 0; vi = next_[vi]) {
            if (key_[vi] != key || vi == ia || vi == ib || vi == ic) continue;
            const Eigen::Vector3d p = X.row(vi);
            if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
            const Eigen::Vector3d ap = p - a;
            const double d = n.dot(ap);
            if (std::abs(d) >= thickness) continue;
            const double wb = ap.cross(c - a).dot(N) / nn;
            const double wc = (b - a).cross(ap).dot(N) / nn;
            if (wb < 0 || wc < 0 || wb + wc > 1) continue;
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

}  // namespace clothwind::sim
