#include "learn/fly_direction.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

namespace clothwind::learn {
namespace {

// The frames as CV_64F planes, checked.
std::vector<cv::Mat> AsDouble(const std::vector<cv::Mat>& frames) {
  if (frames.size() < 4) {
    throw std::invalid_argument("EstimateFlyDirection: expected at least 4 frames, got " +
                                std::to_string(frames.size()));
  }
  const cv::Size size = frames[0].size();
  std::vector<cv::Mat> out(frames.size());
  for (size_t t = 0; t < frames.size(); ++t) {
    const cv::Mat& f = frames[t];
    if (f.type() != CV_8UC1 && f.type() != CV_32FC1) {
      throw std::invalid_argument("EstimateFlyDirection: frame " + std::to_string(t) +
                                  " is not single-channel CV_8UC1 or CV_32FC1");
    }
    if (f.size() != size || size.width < 3) {
      throw std::invalid_argument("EstimateFlyDirection: frame " + std::to_string(t) + " is " +
                                  std::to_string(f.cols) + "x" + std::to_string(f.rows) + ", expected " +
                                  std::to_string(size.width) + "x" + std::to_string(size.height) +
                                  " with at least 3 columns, as frame 0");
    }
    f.convertTo(out[t], CV_64F);
  }
  return out;
}

double MotionSkewness(const std::vector<cv::Mat>& f) {
  const cv::Mat sd = TemporalStd(f);
  cv::Mat profile;
  cv::reduce(sd, profile, 0, cv::REDUCE_SUM, CV_64F);
  std::vector<double> m(profile.begin<double>(), profile.end<double>());
  std::vector<double> sorted = m;
  std::sort(sorted.begin(), sorted.end());
  const double floor = sorted[sorted.size() / 10];
  double w = 0, mu = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    m[i] = std::max(m[i] - floor, 0.0);
    w += m[i];
    mu += static_cast<double>(i) * m[i];
  }
  if (!(w > 0)) return 0.0;
  mu /= w;
  double m2 = 0, m3 = 0;
  for (size_t i = 0; i < m.size(); ++i) {
    const double d = static_cast<double>(i) - mu;
    m2 += m[i] * d * d;
    m3 += m[i] * d * d * d;
  }
  m2 /= w;
  m3 /= w;
  return m2 > 0 ? m3 / std::pow(m2, 1.5) : 0.0;
}

double PhaseStep(const std::vector<cv::Mat>& f) {
  const int T = static_cast<int>(f.size());
  const int rows = f[0].rows, cols = f[0].cols;
  const size_t pixels = static_cast<size_t>(rows) * cols;
  // Each frame less the clip's mean, as one contiguous T x pixels array.
  std::vector<double> d(static_cast<size_t>(T) * pixels, 0.0), mean(pixels, 0.0);
  for (int t = 0; t < T; ++t) {
    for (int y = 0; y < rows; ++y) {
      const double* row = f[t].ptr<double>(y);
      std::copy(row, row + cols, d.data() + t * pixels + static_cast<size_t>(y) * cols);
    }
    for (size_t i = 0; i < pixels; ++i) mean[i] += d[t * pixels + i] / T;
  }
  for (int t = 0; t < T; ++t)
    for (size_t i = 0; i < pixels; ++i) d[t * pixels + i] -= mean[i];
  std::complex<double> total(0, 0);
  std::vector<double> re(pixels), im(pixels);
  for (int k = 1; k <= T / 2 - 1; ++k) {
    std::fill(re.begin(), re.end(), 0.0);
    std::fill(im.begin(), im.end(), 0.0);
    for (int t = 0; t < T; ++t) {
      const double c = std::cos(2 * M_PI * k * t / T), s = -std::sin(2 * M_PI * k * t / T);
      const double* dt = d.data() + t * pixels;
      for (size_t i = 0; i < pixels; ++i) {
        re[i] += dt[i] * c;
        im[i] += dt[i] * s;
      }
    }
    // z(x + 1) conj(z(x)) summed along every row.
    double sum_re = 0, sum_im = 0;
    for (int y = 0; y < rows; ++y) {
      const size_t base = static_cast<size_t>(y) * cols;
      for (int x = 0; x + 1 < cols; ++x) {
        const size_t a = base + x + 1, b = base + x;
        sum_re += re[a] * re[b] + im[a] * im[b];
        sum_im += im[a] * re[b] - re[a] * im[b];
      }
    }
    total += std::complex<double>(sum_re, sum_im);
  }
  return std::abs(total) > 0 ? std::arg(total) : 0.0;
}

}  // namespace

cv::Mat TemporalStd(const std::vector<cv::Mat>& frames) {
  const double n = static_cast<double>(frames.size());
  cv::Mat sum = cv::Mat::zeros(frames[0].size(), CV_64F), sq = sum.clone();
  for (const cv::Mat& x : frames) {
    sum += x;
    sq += x.mul(x);
  }
  cv::Mat mean = sum / n, var = sq / n - mean.mul(mean), sd;
  cv::max(var, 0.0, var);  // rounding can make a still pixel's variance slightly negative
  cv::sqrt(var, sd);
  return sd;
}

std::string FlyDirectionName(FlyDirection direction) {
  return direction == FlyDirection::kRight ? "right" : "left";
}

std::string FlagFliesName(FlagFlies flag_flies) {
  switch (flag_flies) {
    case FlagFlies::kRight: return "right";
    case FlagFlies::kLeft: return "left";
    case FlagFlies::kAuto: return "auto";
  }
  return "right";
}

FlagFlies FlagFliesFromName(const std::string& name, const std::string& where) {
  for (const FlagFlies f : {FlagFlies::kRight, FlagFlies::kLeft, FlagFlies::kAuto}) {
    if (name == FlagFliesName(f)) return f;
  }
  throw std::invalid_argument(where + ": expected right, left or auto, got '" + name + "'");
}

FlyDirectionCues EstimateFlyDirection(const std::vector<cv::Mat>& frames) {
  const std::vector<cv::Mat> f = AsDouble(frames);
  FlyDirectionCues c;
  c.motion_skewness = MotionSkewness(f);
  c.phase_step = PhaseStep(f);
  c.score = kSkewnessWeight * -c.motion_skewness + kPhaseWeight * -c.phase_step;
  c.direction = c.score >= 0 ? FlyDirection::kRight : FlyDirection::kLeft;
  return c;
}

std::optional<FlyDirection> FlyDirectionFromWind(double wind_direction, double camera_heading, double end_on) {
  // A NaN end-on angle clamps to NaN, compares false and would make no wind end-on: none known.
  if (!std::isfinite(wind_direction) || !std::isfinite(camera_heading) || std::isnan(end_on)) return std::nullopt;
  // The wind's component along the picture's right, heading - 90 deg: cos(wind - heading + 90 deg).
  const double across = std::sin(camera_heading - wind_direction);
  if (std::abs(across) <= std::sin(std::clamp(end_on, 0.0, M_PI / 2))) return std::nullopt;
  return across > 0 ? FlyDirection::kRight : FlyDirection::kLeft;
}

}  // namespace clothwind::learn
