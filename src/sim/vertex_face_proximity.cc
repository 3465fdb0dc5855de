#include "sim/vertex_face_proximity.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace clothwind::sim {
namespace {

constexpr std::int64_t kOffset = 1 << 20;  // cells within +-2^20 per axis get exact keys

std::uint64_t CellKey(std::int64_t i, std::int64_t j, std::int64_t k) {
  auto wrap = [](std::int64_t a) { return static_cast<std::uint64_t>((a + kOffset) & ((1 << 21) - 1)); };
  return (wrap(i) << 42) | (wrap(j) << 21) | wrap(k);
}

}  // namespace

VertexFaceProximity::VertexFaceProximity(const Eigen::MatrixX3i& F, int num_vertices)
    : F_(F), num_vertices_(num_vertices) {
  cells_.reserve(num_vertices);
}

void VertexFaceProximity::Update(const Eigen::MatrixX3d& X, double thickness) {
  pairs_.clear();
  if (!(thickness > 0) || F_.rows() == 0) return;
  // Cell size: the mean edge length (a face's box then spans a few cells), at least 2 thickness.
  double mean_edge = 0;
  for (int f = 0; f < F_.rows(); ++f)
    mean_edge += (X.row(F_(f, 0)) - X.row(F_(f, 1))).norm();
  mean_edge /= F_.rows();
  const double cell = std::max(mean_edge, 2 * thickness);
  const double inv = 1.0 / cell;
  cells_.clear();
  for (int i = 0; i < num_vertices_; ++i) {
    cells_.emplace_back(CellKey(static_cast<std::int64_t>(std::floor(X(i, 0) * inv)),
                                static_cast<std::int64_t>(std::floor(X(i, 1) * inv)),
                                static_cast<std::int64_t>(std::floor(X(i, 2) * inv))),
                        i);
  }
  std::sort(cells_.begin(), cells_.end());
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
    const size_t first_pair = pairs_.size();
    for (auto i = i0; i <= i1; ++i)
      for (auto j = j0; j <= j1; ++j)
        for (auto k = k0; k <= k1; ++k) {
          const std::uint64_t key = CellKey(i, j, k);
          auto it = std::lower_bound(cells_.begin(), cells_.end(), std::make_pair(key, -1));
          for (; it != cells_.end() && it->first == key; ++it) {
            const int vi = it->second;
            if (vi == ia || vi == ib || vi == ic) continue;
            const Eigen::Vector3d p = X.row(vi);
            if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
            const Eigen::Vector3d ap = p - a;
            const double d = n.dot(ap);
            if (std::abs(d) >= thickness) continue;
            const double wb = ap.cross(c - a).dot(N) / nn;
            const double wc = (b - a).cross(ap).dot(N) / nn;
            if (wb < 0 || wc < 0 || wb + wc > 1) continue;
            pairs_.push_back({vi, f, d >= 0 ? 1.0 : -1.0});
          }
        }
    // Distinct keys may alias (wrap-around) only for absurd coordinates; sort for determinism.
    std::sort(pairs_.begin() + first_pair, pairs_.end(),
              [](const Pair& l, const Pair& r) { return l.vertex < r.vertex; });
    pairs_.erase(std::unique(pairs_.begin() + first_pair, pairs_.end(),
                             [](const Pair& l, const Pair& r) { return l.vertex == r.vertex; }),
                 pairs_.end());
  }
}

}  // namespace clothwind::sim
