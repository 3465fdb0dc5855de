#include "sim/flag_metrics.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

namespace clothwind::sim {
namespace {

int Nearest(const Eigen::MatrixX2f& uv, float u, float v) {
  int best = -1;
  float best_d = 0;
  for (int i = 0; i < uv.rows(); ++i) {
    const float d = (uv(i, 0) - u) * (uv(i, 0) - u) + (uv(i, 1) - v) * (uv(i, 1) - v);
    if (best < 0 || d < best_d) best = i, best_d = d;
  }
  return best;
}

double Rms(const std::vector<double>& s) {
  double m = 0;
  for (double x : s) m += x / s.size();
  double r = 0;
  for (double x : s) r += (x - m) * (x - m) / s.size();
  return std::sqrt(r);
}

// Power at frequency bins k = 1..n/2 of the mean-removed, Hann-windowed signal.
std::vector<double> Periodogram(const std::vector<double>& s) {
  const int n = static_cast<int>(s.size());
  double m = 0;
  for (double x : s) m += x / n;
  std::vector<double> w(n);
  for (int i = 0; i < n; ++i) w[i] = (s[i] - m) * 0.5 * (1 - std::cos(2 * M_PI * i / (n - 1)));
  std::vector<double> p(n / 2 + 1, 0.0);
  for (int k = 1; k <= n / 2; ++k) {
    double re = 0, im = 0;
    for (int i = 0; i < n; ++i) {
      re += w[i] * std::cos(2 * M_PI * k * i / n);
      im -= w[i] * std::sin(2 * M_PI * k * i / n);
    }
    p[k] = re * re + im * im;
  }
  return p;
}

}  // namespace

FlagLandmarks FindFlagLandmarks(const Eigen::MatrixX2f& uv) {
  if (uv.rows() == 0) throw std::invalid_argument("FindFlagLandmarks: empty mesh");
  const float u0 = uv.col(0).minCoeff(), u1 = uv.col(0).maxCoeff();
  const float v0 = uv.col(1).minCoeff(), v1 = uv.col(1).maxCoeff();
  FlagLandmarks l;
  l.hoist_mid = Nearest(uv, u0, 0.5f * (v0 + v1));
  l.fly_mid = Nearest(uv, u1, 0.5f * (v0 + v1));
  l.fly_upper = Nearest(uv, u1, v1);
  return l;
}

FlagMotion MeasureFlagMotion(const Trajectory& t, const Eigen::Vector3d& wind_dir, int first) {
  const int end = t.num_frames();
  if (first < 0 || end - first < 4) throw std::invalid_argument("MeasureFlagMotion: window too short");
  const FlagLandmarks l = FindFlagLandmarks(t.uv);
  Eigen::Vector3d along(wind_dir.x(), wind_dir.y(), 0);
  if (along.norm() < 1e-9) along = Eigen::Vector3d::UnitX();
  along.normalize();
  const Eigen::Vector3d lateral = Eigen::Vector3d::UnitZ().cross(along);
  FlagMotion m;
  m.frames = end - first;
  std::vector<double> lat, vert;
  for (int f = first; f < end; ++f) {
    const Eigen::Vector3d hoist = t.frames[f].row(l.hoist_mid).cast<double>().transpose();
    const Eigen::Vector3d fly = t.frames[f].row(l.fly_mid).cast<double>().transpose();
    const Eigen::Vector3d d = fly - hoist;
    m.droop_deg += std::atan2(-d.z(), std::hypot(d.x(), d.y())) * 180.0 / M_PI / m.frames;
    const Eigen::Vector3d c = t.frames[f].row(l.fly_upper).cast<double>().transpose();
    lat.push_back(c.dot(lateral));
    vert.push_back(c.z());
  }
  m.lateral_rms = Rms(lat);
  m.vertical_rms = Rms(vert);
  const auto pl = Periodogram(lat), pv = Periodogram(vert);
  const int n = m.frames;
  const double df = 1.0 / (n * t.frame_time);
  double total = 0, weighted = 0, best = -1;
  for (size_t k = 1; k < pl.size(); ++k) {
    const double f = k * df;
    if (f < 0.2 || f > 5.0) continue;
    const double p = pl[k] + pv[k];
    total += p;
    weighted += p * f;
    if (p > best) best = p, m.peak_hz = f;
  }
  m.dominant_hz = total > 0 ? weighted / total : 0;
  m.peak_fraction = total > 0 ? best / total : 0;
  return m;
}

}  // namespace clothwind::sim
