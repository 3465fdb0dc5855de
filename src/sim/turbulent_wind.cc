#include "sim/turbulent_wind.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "common/random.h"

namespace clothwind::sim {
namespace {

// k_e L_u for the von Kármán spectrum: sqrt(pi) Gamma(5/6) / Gamma(1/3).
double KeTimesL() { return std::sqrt(M_PI) * std::tgamma(5.0 / 6.0) / std::tgamma(1.0 / 3.0); }

Eigen::Vector3d RandomUnit(Rng& g) {
  const double z = g.Uniform(-1.0, 1.0);
  const double phi = g.Uniform(0.0, 2.0 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// Along-wind, across-wind (horizontal), up. For a vertical or zero mean wind: x, y, z.
Eigen::Matrix3d WindFrame(const Eigen::Vector3d& mean) {
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  if (mean.norm() > 1e-9) e1 = mean.normalized();
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e3 = up - up.dot(e1) * e1;
  if (e3.norm() < 1e-6) e3 = Eigen::Vector3d::UnitY() - e1.y() * e1;
  e3.normalize();
  Eigen::Matrix3d f;
  f.col(0) = e1;
  f.col(1) = e3.cross(e1);
  f.col(2) = e3;
  return f;
}

}  // namespace

TurbulentWind::TurbulentWind(const TurbulenceParams& p, const Eigen::Vector3d& mean_velocity)
    : mean_(mean_velocity), frame_(WindFrame(mean_velocity)) {
  if (!(p.intensity >= 0.0 && p.intensity <= kMaxTurbulenceIntensity)) {
    throw std::invalid_argument("turbulence intensity must be in 0.." + std::to_string(kMaxTurbulenceIntensity) +
                                ", got " + std::to_string(p.intensity));
  }
  if (!(p.length_scale >= kMinTurbulenceLengthScale && p.length_scale <= kMaxTurbulenceLengthScale)) {
    throw std::invalid_argument("turbulence length_scale must be in 0.01..10000 m, got " +
                                std::to_string(p.length_scale));
  }
  if (p.modes < 1) throw std::invalid_argument("turbulence needs at least one mode");
  const double sigma_u = p.intensity * mean_velocity.norm();
  if (sigma_u == 0.0) return;  // No fluctuation: Velocity() returns zero.

  // Shells log-spaced over [k_e/10, 200 k_e]: below, the k^4 range holds < 1e-5 of the
  // energy; above, the k^-5/3 tail is scales far below a flag's size (L_u/270 ~ cm).
  const double ke = KeTimesL() / p.length_scale;
  const double lo = std::log(0.1 * ke), hi = std::log(200.0 * ke);
  Rng g(p.seed);
  const int n = p.modes;
  std::vector<Eigen::Vector3d> raw(n), wavevector(n);
  std::vector<double> phase(n);
  Eigen::Vector3d variance = Eigen::Vector3d::Zero();  // realised, in the wind frame
  for (int i = 0; i < n; ++i) {
    const double a = lo + (hi - lo) * i / n, b = lo + (hi - lo) * (i + 1) / n;
    const double k = std::exp(0.5 * (a + b));
    const double dk = std::exp(b) - std::exp(a);
    const double x = k / ke;
    const double energy = std::pow(x, 4) / std::pow(1.0 + x * x, 17.0 / 6.0);
    const Eigen::Vector3d dir = RandomUnit(g);
    // Polarisation: a random unit vector perpendicular to the wavevector (divergence-free until
    // the anisotropic rescaling below, which breaks that a little: docs/scenes.md).
    Eigen::Vector3d helper = RandomUnit(g);
    Eigen::Vector3d pol = helper - helper.dot(dir) * dir;
    if (pol.norm() < 1e-6) pol = dir.unitOrthogonal();
    pol.normalize();
    raw[i] = std::sqrt(energy * dk) * pol;
    wavevector[i] = k * dir;
    phase[i] = g.Uniform(0.0, 2.0 * M_PI);
    const Eigen::Vector3d in_frame = frame_.transpose() * raw[i];
    variance += 0.5 * in_frame.cwiseAbs2();  // <cos^2> = 1/2
  }
  Eigen::Vector3d scale;
  for (int c = 0; c < 3; ++c) {
    const double target = sigma_u * p.component_ratios[c];
    scale[c] = variance[c] > 0.0 ? target / std::sqrt(variance[c]) : 0.0;
  }
  const Eigen::Matrix3d to_world = frame_ * scale.asDiagonal() * frame_.transpose();
  kx_.resize(n), ky_.resize(n), kz_.resize(n), phase_.resize(n);
  ax_.resize(n), ay_.resize(n), az_.resize(n);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d amp = to_world * raw[i];
    kx_[i] = wavevector[i].x(), ky_[i] = wavevector[i].y(), kz_[i] = wavevector[i].z();
    phase_[i] = phase[i];
    ax_[i] = static_cast<float>(amp.x()), ay_[i] = static_cast<float>(amp.y());
    az_[i] = static_cast<float>(amp.z());
  }
}

Eigen::Vector3d TurbulentWind::Velocity(const Eigen::Vector3d& x, double t) const {
  if (kx_.size() == 0) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d xi = x - mean_ * t;
  Eigen::ArrayXd arg = kx_ * xi.x() + ky_ * xi.y() + kz_ * xi.z() + phase_;
  // arg - 2 pi round(arg / 2 pi), rounding by the 1.5 * 2^52 trick: exact for |arg| < 2^51,
  // vectorises without SSE4.1's round instruction (the compiler keeps the order: no fast-math).
  constexpr double kRound = 6755399441055744.0;
  arg -= (2.0 * M_PI) * (((arg * (0.5 / M_PI)) + kRound) - kRound);
  const Eigen::ArrayXf c = arg.cast<float>().cos();
  return {static_cast<double>((ax_ * c).sum()), static_cast<double>((ay_ * c).sum()),
          static_cast<double>((az_ * c).sum())};
}

double TurbulentWind::LongitudinalCorrelation(double r, double length_scale) {
  const double x = std::abs(r) * KeTimesL() / length_scale;
  if (x < 1e-12) return 1.0;
  return std::pow(2.0, 2.0 / 3.0) / std::tgamma(1.0 / 3.0) * std::cbrt(x) *
         std::cyl_bessel_k(1.0 / 3.0, x);
}

}  // namespace clothwind::sim
