#include "sensors/synthetic_session.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "common/random.h"

namespace clothwind::sensors {
namespace {

// One exact Ornstein-Uhlenbeck step of length dt towards mean mu.
// The project's Rng, not <random>'s distributions (implementation-defined): a session is the
// same with every standard library.
double OuStep(double x, double mu, double sigma, double tau, double dt, Rng& rng) {
  const double a = std::exp(-dt / tau);
  return mu + (x - mu) * a + sigma * std::sqrt(std::max(0.0, 1.0 - a * a)) * rng.Normal();
}

void Check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("synthetic session: " + what);
}

}  // namespace

SyntheticWind::SyntheticWind(const SyntheticSessionOptions& o) : dt_(0.02) {
  Check(o.duration > 0.0, "duration must be > 0 s");
  Check(o.wind_drift_tau > 0.0 && o.turbulence_tau > 0.0, "correlation times must be > 0 s");
  Rng rng(o.seed);
  const size_t n = static_cast<size_t>(std::ceil((o.duration + 5.0) / dt_)) + 1;
  speed_.resize(n);
  angle_.resize(n);
  phase_.resize(n);
  double drift = o.wind_base, turbulence = 0.0, angle = o.direction_from;
  for (size_t i = 0; i < n; ++i) {
    if (i > 0) {
      drift = OuStep(drift, o.wind_base, o.wind_drift_std, o.wind_drift_tau, dt_, rng);
      turbulence = OuStep(turbulence, 0.0, 1.0, o.turbulence_tau, dt_, rng);
      angle = OuStep(angle, o.direction_from, o.direction_std, 30.0, dt_, rng);
    }
    const double mean = std::max(0.3, drift);
    speed_[i] = std::max(0.2, mean * (1.0 + o.turbulence_intensity * turbulence));
    angle_[i] = angle;
    phase_[i] = i == 0 ? 0.0
                       : phase_[i - 1] + M_PI * dt_ * (FlutterFrequency(speed_[i - 1]) + FlutterFrequency(speed_[i]));
  }
}

double SyntheticWind::FlutterFrequency(double speed) { return 0.5 + 0.35 * std::max(0.0, speed); }

double SyntheticWind::Interp(const std::vector<double>& v, double t) const {
  const double x = std::clamp(t / dt_, 0.0, static_cast<double>(v.size() - 1));
  const size_t i = std::min(static_cast<size_t>(x), v.size() - 2);
  const double f = x - static_cast<double>(i);
  return v[i] * (1.0 - f) + v[i + 1] * f;
}

double SyntheticWind::Speed(double t) const { return Interp(speed_, t); }

double SyntheticWind::FromAngle(double t) const {
  const double a = std::fmod(Interp(angle_, t), 360.0);
  return a < 0.0 ? a + 360.0 : a;
}

double SyntheticWind::FlutterPhase(double t) const { return Interp(phase_, t); }

double SyntheticWind::MeanSpeed(double t0, double t1) const {
  if (t1 <= t0) return Speed(t0);
  const int steps = std::max(1, static_cast<int>(std::ceil((t1 - t0) / dt_)));
  double sum = 0.0;  // trapezoid rule on the grid's resolution
  for (int k = 0; k <= steps; ++k) sum += Speed(t0 + (t1 - t0) * k / steps) * ((k == 0 || k == steps) ? 0.5 : 1.0);
  return sum / steps;
}

cv::Mat ProceduralFlagGenerator::Render(double t, const SyntheticWind& wind, int width, int height) const {
  cv::Mat img(height, width, CV_8UC3);
  // Sky: a vertical gradient; ground: a green band.
  const int ground = static_cast<int>(0.85 * height);
  for (int r = 0; r < height; ++r) {
    const double s = static_cast<double>(r) / height;
    const cv::Vec3b c = r < ground ? cv::Vec3b(static_cast<uint8_t>(225 + 20 * s), static_cast<uint8_t>(180 + 45 * s),
                                               static_cast<uint8_t>(120 + 80 * s))
                                   : cv::Vec3b(60, 120, 70);
    img.row(r).setTo(cv::Scalar(c[0], c[1], c[2]));
  }
  const double pole_x = 0.22 * width, top = 0.2 * height;
  const double length = 0.58 * width, cloth = 0.32 * height;
  cv::line(img, cv::Point(static_cast<int>(pole_x), static_cast<int>(top - 0.04 * height)),
           cv::Point(static_cast<int>(pole_x), ground), cv::Scalar(90, 90, 90), std::max(2, width / 110), cv::LINE_AA);

  const double speed = wind.Speed(t), phase = wind.FlutterPhase(t);
  const double droop = std::exp(-speed / 2.5);  // light wind: the flag hangs
  constexpr int nu = 32, nv = 9;
  constexpr double waves = 1.3;                 // wavelengths along the flag
  auto point = [&](double u, double v, double* shade) {
    const double k = 2.0 * M_PI * waves * u - phase;
    const double amplitude = (0.10 + 0.10 * (1.0 - droop)) * cloth * u;
    const double x = pole_x + length * u * (1.0 - 0.55 * droop * u) * (1.0 - 0.04 * (1.0 - std::cos(k)));
    const double y = top + v * cloth + amplitude * std::sin(k) + 0.9 * cloth * droop * u * u;
    if (shade) *shade = 0.72 + 0.28 * std::cos(k);  // light from the front-left on the wave's slope
    return cv::Point2d(x, y);
  };
  static const cv::Vec3d kStripes[3] = {{40, 40, 200}, {235, 235, 235}, {150, 70, 25}};  // BGR bands
  constexpr int kShift = 4;  // sub-pixel vertices (1/16 px) so slow motion is smooth
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double u0 = static_cast<double>(i) / nu, u1 = static_cast<double>(i + 1) / nu;
      const double v0 = static_cast<double>(j) / nv, v1 = static_cast<double>(j + 1) / nv;
      double shade;
      point(0.5 * (u0 + u1), 0.5 * (v0 + v1), &shade);
      const cv::Point2d p[4] = {point(u0, v0, nullptr), point(u1, v0, nullptr), point(u1, v1, nullptr),
                                point(u0, v1, nullptr)};
      cv::Point q[4];
      for (int k = 0; k < 4; ++k) q[k] = cv::Point(cvRound(p[k].x * (1 << kShift)), cvRound(p[k].y * (1 << kShift)));
      const cv::Vec3d c = kStripes[std::min(2, j * 3 / nv)] * shade;
      cv::fillConvexPoly(img, q, 4, cv::Scalar(c[0], c[1], c[2]), cv::LINE_AA, kShift);
    }
  }
  return img;
}

std::string FormatMwvSentence(double angle_deg, double speed_mps) {
  char body[64];
  std::snprintf(body, sizeof body, "WIMWV,%.1f,R,%.2f,M,A", angle_deg, speed_mps);
  uint8_t checksum = 0;
  for (const char* c = body; *c; ++c) checksum ^= static_cast<uint8_t>(*c);
  char sentence[80];
  std::snprintf(sentence, sizeof sentence, "$%s*%02X", body, checksum);
  return sentence;
}

SyntheticSession::SyntheticSession(const SyntheticSessionOptions& o,
                                   std::shared_ptr<const FlagFrameGenerator> generator)
    : options_(o), wind_(o), generator_(std::move(generator)) {
  // Bounded, so that nonsense fails here and not as an allocation of 10^12 frames, images of
  // gigabytes (the Clip message's limit, see sdn_node) or stamps outside ROS time's 32 bits.
  Check(o.fps > 0.0 && o.fps <= 1000.0, "fps must be in (0, 1000] Hz, got " + std::to_string(o.fps));
  Check(o.width >= 16 && o.height >= 16 && o.width <= 16384 && o.height <= 16384,
        "image must be 16..16384 px a side, got " + std::to_string(o.width) + "x" + std::to_string(o.height));
  // At least 1 s: a frame's jitter may place it before the start, and a start of a few
  // milliseconds then failed mid-write for some seeds (a stamp before ROS time 0).
  Check(o.start_time >= 1.0 && o.start_time + o.duration + 10.0 < 4294967295.0,
        "start time must be >= 1 s and end before 2106 (ROS time is 32-bit seconds), got " +
            std::to_string(o.start_time) + " s");
  Check(o.anemometer_rate > 0.0, "anemometer rate must be > 0 Hz");
  Check(o.frame_jitter >= 0.0 && o.frame_jitter < 0.25 / o.fps, "frame jitter must be in [0, 1/(4 fps))");
  Check(o.drop_probability >= 0.0 && o.drop_probability < 1.0, "drop probability must be in [0, 1)");
  if (!generator_) generator_ = std::make_shared<ProceduralFlagGenerator>();
  // Frame stamps use their own random stream so changing the wind settings keeps the timing.
  Rng rng(o.seed * 0x9E3779B97F4A7C15ull + 1);
  const auto frames = static_cast<size_t>(std::floor(o.duration * o.fps));
  for (size_t i = 0; i < frames; ++i) {
    const double jitter = o.frame_jitter * rng.Normal();  // drawn either way: the stream stays in step
    const double j = o.frame_jitter > 0.0 ? std::clamp(jitter, -2 * o.frame_jitter, 2 * o.frame_jitter) : 0.0;
    const bool drop = rng.Uniform() < o.drop_probability;
    if (!drop) frame_stamps_.push_back(o.start_time + i / o.fps + j);
  }
  const auto sentences = static_cast<size_t>(std::floor(o.duration * o.anemometer_rate));
  for (size_t k = 1; k <= sentences; ++k) {
    const double t = k / o.anemometer_rate;  // since start: the interval (t - 1/rate, t]
    SyntheticReading r;
    r.speed = std::round(wind_.MeanSpeed(t - 1.0 / o.anemometer_rate, t) * 100.0) / 100.0;
    r.angle = std::fmod(std::round(wind_.FromAngle(t) * 10.0) / 10.0, 360.0);
    r.measured_at = o.start_time + t;
    r.stamp = r.measured_at + o.anemometer_latency;
    r.sentence = FormatMwvSentence(r.angle, r.speed);
    if (r.stamp <= o.start_time + o.duration) readings_.push_back(r);
  }
}

cv::Mat SyntheticSession::RenderFrame(size_t i) const {
  return generator_->Render(frame_stamps_.at(i) - options_.start_time, wind_, options_.width, options_.height);
}

}  // namespace clothwind::sensors
