#include "data/cloth_animation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <stdexcept>

#include "sim/mesh.h"

namespace clothwind::data {

namespace fs = std::filesystem;

Eigen::MatrixXd NormalizeTextureCoordinates(const Eigen::MatrixXd& U, const Eigen::Vector2d& lo,
                                            const Eigen::Vector2d& hi) {
  if (U.cols() != 2) throw std::invalid_argument("texture coordinates: expected #V by 2");
  if (!(hi.x() > lo.x() && hi.y() > lo.y()))
    throw std::invalid_argument("texture coordinates: material space has no extent");
  Eigen::MatrixXd T(U.rows(), 2);
  for (int c = 0; c < 2; ++c) T.col(c) = (U.col(c).array() - lo[c]) / (hi[c] - lo[c]);
  return T;
}

namespace {
// The material-space box of the vertices the faces F use (#F by 3 into U's rows). Why not all of
// U: an OBJ vertex no face uses (a stray point of a modelling tool) sized a 1 m cloth as 5 m,
// rendered small, framed for the larger one, and a correct --zeta was refused.
void Bounds(const Eigen::MatrixXd& U, const Eigen::MatrixXi& F, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  lo->setConstant(std::numeric_limits<double>::infinity());
  hi->setConstant(-std::numeric_limits<double>::infinity());
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < F.cols(); ++c) {
      const int v = F(f, c);
      if (v < 0 || v >= U.rows())
        throw std::invalid_argument("face " + std::to_string(f) + " names vertex " + std::to_string(v) + " of " +
                                    std::to_string(U.rows()));
      *lo = lo->cwiseMin(U.row(v).transpose());
      *hi = hi->cwiseMax(U.row(v).transpose());
    }
}
}  // namespace

ClothAnimation AnimationFromTrajectory(const sim::Trajectory& t, int first, int count) {
  if (count < 0) count = t.num_frames() - first;
  if (first < 0 || count < 1 || first + count > t.num_frames())
    throw std::out_of_range("trajectory frames [" + std::to_string(first) + ", " +
                            std::to_string(first + count) + ") outside its " +
                            std::to_string(t.num_frames()) + " frames");
  ClothAnimation a;
  a.frame_time = t.frame_time;
  a.F = t.faces;
  const Eigen::MatrixXd U = t.uv.cast<double>();
  Eigen::Vector2d lo, hi;
  Bounds(U, t.faces, &lo, &hi);
  a.UV = NormalizeTextureCoordinates(U, lo, hi);
  a.rest_size = hi - lo;
  a.frames.resize(count);
  for (int i = 0; i < count; ++i) a.frames[i].V = t.frames[first + i].cast<double>();
  return a;
}

ClothAnimation ReadObjSequence(const std::string& folder, int cloth, double frame_time) {
  if (!(frame_time > 0)) throw std::invalid_argument("OBJ sequence: frame_time must be > 0 s");
  ClothAnimation a;
  a.frame_time = frame_time;
  Eigen::Vector2d lo, hi;
  for (int f = 0;; ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "%04d_%02d.obj", f, cloth);
    const fs::path path = fs::path(folder) / name;
    if (!fs::exists(path)) break;
    const sim::Mesh m = sim::ReadObj(path.string(), /*topology=*/false);  // drawn, not simulated
    const Eigen::MatrixXd U = m.U;
    if (f == 0) {
      Bounds(U, m.F, &lo, &hi);
      a.rest_size = hi - lo;
    }
    ClothFrame frame;
    frame.V = m.V;
    frame.F = m.F;
    frame.UV = NormalizeTextureCoordinates(U, lo, hi);
    a.frames.push_back(std::move(frame));
  }
  if (a.frames.empty()) {
    char name[32];
    std::snprintf(name, sizeof(name), "0000_%02d.obj", cloth);
    throw std::runtime_error("OBJ sequence: " + (fs::path(folder) / name).string() +
                             " not found (expected frames NNNN_CC.obj from 0000)");
  }
  // A frame missing in the middle ended the sequence there, and the frames after it were
  // dropped without a word.
  const int found = static_cast<int>(a.frames.size());
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    const std::string file = e.path().filename().string();
    int f = -1, c = -1;
    char tail = 0;
    if (std::sscanf(file.c_str(), "%d_%d.ob%c", &f, &c, &tail) == 3 && tail == 'j' && c == cloth && f > found) {
      char name[32];
      std::snprintf(name, sizeof(name), "%04d_%02d.obj", found, cloth);
      throw std::runtime_error("OBJ sequence: " + (fs::path(folder) / name).string() + " is missing, but " +
                               file + " comes later (frames NNNN_CC.obj must be numbered without gaps)");
    }
  }
  // Frames that keep the first frame's topology share its faces and texture coordinates.
  a.F = a.frames[0].F;
  a.UV = a.frames[0].UV;
  for (auto& frame : a.frames) {
    if (frame.F.rows() == a.F.rows() && frame.F == a.F && frame.UV.rows() == a.UV.rows()) {
      frame.F.resize(0, 3);
      frame.UV.resize(0, 2);
    }
  }
  return a;
}

ClothFrame FrameAt(const ClothAnimation& a, double t) {
  if (a.frames.empty()) throw std::invalid_argument("FrameAt: empty animation");
  const double x = std::clamp(t / a.frame_time, 0.0, static_cast<double>(a.frames.size() - 1));
  const int i = std::min(static_cast<int>(std::floor(x)), a.num_frames() - 1);
  const double w = x - i;
  auto full = [&](int k) {
    ClothFrame f = a.frames[k];
    if (f.F.size() == 0) f.F = a.F;
    if (f.UV.size() == 0) f.UV = a.UV;
    return f;
  };
  ClothFrame f0 = full(i);
  if (w < 1e-9 || i + 1 >= a.num_frames()) return f0;
  const ClothFrame& next = a.frames[i + 1];
  const Eigen::MatrixXi& next_F = next.F.size() == 0 ? a.F : next.F;
  const bool same = next.V.rows() == f0.V.rows() && next_F.rows() == f0.F.rows() && next_F == f0.F;
  if (!same) return w < 0.5 ? f0 : full(i + 1);
  f0.V = (1.0 - w) * f0.V + w * next.V;
  return f0;
}

std::vector<cv::Mat> RenderAnimation(render::Renderer* renderer, const ClothAnimation& a,
                                     double start, int count, double fps) {
  if (count < 1 || !(fps > 0)) throw std::invalid_argument("RenderAnimation: count >= 1, fps > 0");
  std::vector<cv::Mat> images;
  images.reserve(count);
  for (int k = 0; k < count; ++k) {
    const ClothFrame f = FrameAt(a, start + k / fps);
    images.push_back(renderer->RenderFrame(f.V, f.F, f.UV));
  }
  return images;
}

}  // namespace clothwind::data
