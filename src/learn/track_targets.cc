#include "learn/track_targets.h"

#include <cmath>
#include <complex>
#include <limits>
#include <stdexcept>
#include <string>

#include "learn/dataset.h"

namespace clothwind::learn {

namespace {

// Appends the rows of `rows` (one array per frame, each `per_row` numbers) to `out`, naming
// `where` + 'name[k]' and what each point holds (`coordinates`, e.g. "x, y") in the error when a
// row is not an array of that length: xy and world share the layout, point after point.
void AppendFrameRows(const nlohmann::json& rows, const std::string& where, const std::string& name, int per_row,
                     const std::string& coordinates, std::vector<float>& out) {
  out.reserve(out.size() + rows.size() * static_cast<size_t>(per_row));
  for (size_t k = 0; k < rows.size(); ++k) {
    if (!rows[k].is_array() || static_cast<int>(rows[k].size()) != per_row)
      throw std::runtime_error(where + "'" + name + "[" + std::to_string(k) + "]' must hold " +
                               std::to_string(per_row) + " coordinates (" + coordinates + " of each grid point)");
    for (size_t c = 0; c < rows[k].size(); ++c) {
      // Finite as a float: 1e300 became inf, and training ran on NaN losses to the end.
      const nlohmann::json& value = rows[k][c];
      const float f = value.is_number() ? value.get<float>() : std::numeric_limits<float>::quiet_NaN();
      if (!std::isfinite(f))
        throw std::runtime_error(where + "'" + name + "[" + std::to_string(k) + "][" + std::to_string(c) +
                                 "]' must be a finite number (as a 32-bit float), got " + value.dump());
      out.push_back(f);
    }
  }
}

}  // namespace

Tracks ReadTracks(const std::filesystem::path& file) {
  const nlohmann::json j = ReadJson(file);
  const std::string where = file.string() + ": field ";
  auto need = [&](const char* key) -> const nlohmann::json& {
    if (!j.contains(key)) throw std::runtime_error(where + "'" + key + "' is missing");
    return j[key];
  };
  // Checked before any value is read: nlohmann's own errors (value() of an array, a string
  // version) named neither the file nor the field.
  if (!j.is_object()) throw std::runtime_error(file.string() + ": expected a JSON object at the top level");
  if (!(j.contains("format") && j["format"] == "clothwind-tracks"))
    throw std::runtime_error(where + "'format' must be \"clothwind-tracks\"");
  if (!(j.contains("version") && j["version"].is_number_integer() && j["version"] == 1))
    throw std::runtime_error(where + "'version' must be the integer 1");
  // A whole number in 1..2^20 (a float like 8.5 would be truncated by get<int>).
  auto count = [&](const nlohmann::json& v, const std::string& name) {
    if (!v.is_number_integer() || v.get<int64_t>() < 1 || v.get<int64_t>() > (1 << 20))
      throw std::runtime_error(where + "'" + name + "' must be a positive integer, got " + v.dump());
    return v.get<int>();
  };
  Tracks t;
  try {
    const nlohmann::json& grid = need("grid");
    if (!grid.is_array() || grid.size() != 2)
      throw std::runtime_error(where + "'grid' must be [cols, rows] of positive integers, got " + grid.dump());
    t.cols = count(grid[0], "grid[0]");
    t.rows = count(grid[1], "grid[1]");
    // points() is an int: 65536 x 65536 wrapped to 0 points, which failed deep in libtorch.
    if (static_cast<int64_t>(t.cols) * t.rows > (1 << 20))
      throw std::runtime_error(where + "'grid' must hold at most 2^20 points, got " + grid.dump());
    t.width = count(need("width"), "width");
    t.height = count(need("height"), "height");
    const nlohmann::json& xy = need("xy");
    if (!xy.is_array() || xy.empty()) throw std::runtime_error(where + "'xy' must be a non-empty array of frames");
    t.frames = static_cast<int>(xy.size());
    AppendFrameRows(xy, where, "xy", 2 * t.points(), "x, y", t.xy);
    if (j.contains("world")) {
      const nlohmann::json& world = j["world"];
      if (!world.is_array() || static_cast<int>(world.size()) != t.frames)
        throw std::runtime_error(where + "'world' must hold one row per frame of 'xy' (" + std::to_string(t.frames) +
                                 ")");
      AppendFrameRows(world, where, "world", 3 * t.points(), "x, y, z", t.world);
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  }
  return t;
}

namespace {

// The periodic Hann window of `frames` samples (the spectral layer's) and its sum.
std::vector<double> Hann(int frames, double* sum) {
  std::vector<double> w(frames);
  *sum = 0;
  for (int t = 0; t < frames; ++t) *sum += w[t] = 0.5 - 0.5 * std::cos(2 * M_PI * t / frames);
  return w;
}

// Σ_t w_t (series_t - mean) e^{-2πi jt/T} / Σ_t w_t: one series' spectrum at bin j.
std::complex<double> BinOf(const std::vector<double>& series, double mean, const std::vector<double>& hann,
                           double hann_sum, int j) {
  // One frame shows no motion (its Hann window is all zero): every bin reads 0.
  if (hann_sum <= 0) return 0.0;
  const int frames = static_cast<int>(series.size());
  std::complex<double> sum = 0;
  for (int t = 0; t < frames; ++t) sum += hann[t] * (series[t] - mean) * std::polar(1.0, -2 * M_PI * j * t / frames);
  return sum / hann_sum;
}

}  // namespace

std::vector<float> WorldTrackTargets(const Tracks& tracks, int first, int frames, bool flipped) {
  const int points = tracks.points();
  if (tracks.world.size() != static_cast<size_t>(tracks.frames) * 3 * points)
    throw std::invalid_argument("WorldTrackTargets: the tracks hold no positions ('world')");
  if (first < 0 || frames < 1 || first + frames > tracks.frames)
    throw std::invalid_argument("WorldTrackTargets: window " + std::to_string(first) + "+" + std::to_string(frames) +
                                " outside tracks of " + std::to_string(tracks.frames) + " frames");
  double hann_sum = 0;
  const std::vector<double> hann = Hann(frames, &hann_sum);
  std::vector<float> out;
  out.reserve(static_cast<size_t>(points) * kWorldTargetsPerPoint);
  std::vector<double> series(frames);
  for (int p = 0; p < points; ++p) {
    std::vector<float> means, amplitudes;
    for (int c = 0; c < 3; ++c) {
      const double sign = c == 1 && flipped ? -1.0 : 1.0;
      double mean = 0;
      for (int t = 0; t < frames; ++t)
        mean += series[t] = sign * tracks.world[(static_cast<size_t>(first + t) * points + p) * 3 + c];
      mean /= frames;
      means.push_back(static_cast<float>(mean));
      for (int j = 1; j <= kTrackBins; ++j)
        amplitudes.push_back(static_cast<float>(std::log(1e-4 + std::abs(BinOf(series, mean, hann, hann_sum, j)))));
    }
    out.insert(out.end(), means.begin(), means.end());
    out.insert(out.end(), amplitudes.begin(), amplitudes.end());
  }
  return out;
}

std::vector<float> TrackTargets(const Tracks& tracks, int first, int frames, const cv::Rect& crop, int source_side,
                                bool flipped, int phase_bins) {
  if (first < 0 || frames < 1 || first + frames > tracks.frames)
    throw std::invalid_argument("TrackTargets: window " + std::to_string(first) + "+" + std::to_string(frames) +
                                " outside tracks of " + std::to_string(tracks.frames) + " frames");
  if (tracks.width != tracks.height || crop.width != crop.height || crop.width < 1 || source_side < 1)
    throw std::invalid_argument("TrackTargets: expected square frames and crops");
  if (phase_bins < 0 || phase_bins > kTrackBins)
    throw std::invalid_argument("TrackTargets: phase_bins must be in [0, " + std::to_string(kTrackBins) + "], got " +
                                std::to_string(phase_bins));
  const int points = tracks.points();
  const double scale = static_cast<double>(source_side) / tracks.width;
  double hann_sum = 0;
  const std::vector<double> hann = Hann(frames, &hann_sum);
  // spectrum[(p * 2 + c) * kTrackBins + j - 1]: coordinate c of point p at bin j, / Σ w_t.
  std::vector<std::complex<double>> spectrum(static_cast<size_t>(points) * 2 * kTrackBins);
  std::vector<float> out;
  out.reserve(TrackTargetCount(points, phase_bins));
  std::vector<double> series(frames);
  for (int p = 0; p < points; ++p) {
    std::vector<float> means, amplitudes;
    for (int c = 0; c < 2; ++c) {
      const double origin = c == 0 ? crop.x : crop.y;
      double mean = 0;
      for (int t = 0; t < frames; ++t) {
        const double pixel = tracks.xy[(static_cast<size_t>(first + t) * points + p) * 2 + c] * scale;
        double unit = 2.0 * (pixel - origin) / crop.width - 1.0;
        if (c == 0 && flipped) unit = -unit;
        mean += series[t] = unit;
      }
      mean /= frames;
      means.push_back(static_cast<float>(mean));
      for (int j = 1; j <= kTrackBins; ++j) {
        const std::complex<double> bin = BinOf(series, mean, hann, hann_sum, j);
        spectrum[(static_cast<size_t>(p) * 2 + c) * kTrackBins + j - 1] = bin;
        amplitudes.push_back(static_cast<float>(std::log(1e-4 + std::abs(bin))));
      }
    }
    out.insert(out.end(), means.begin(), means.end());
    out.insert(out.end(), amplitudes.begin(), amplitudes.end());
  }
  const size_t reference = (static_cast<size_t>(points - 1) * 2 + 1) * kTrackBins;  // the last point's v
  for (int p = 0; p < points; ++p)
    for (int j = 1; j <= phase_bins; ++j) {
      const std::complex<double> r = spectrum[reference + j - 1];
      const std::complex<double> unrotate = std::abs(r) > 1e-12 ? std::conj(r) / std::abs(r) : 1.0;
      for (int c = 0; c < 2; ++c) {
        const std::complex<double> x = spectrum[(static_cast<size_t>(p) * 2 + c) * kTrackBins + j - 1];
        const double amplitude = std::abs(x);  // x / |x| · sqrt|x|, rotated to the reference's phase
        const std::complex<double> z = amplitude > 1e-12 ? x * unrotate / std::sqrt(amplitude) : 0.0;
        out.push_back(static_cast<float>(z.real()));
        out.push_back(static_cast<float>(z.imag()));
      }
    }
  return out;
}

TargetScale ScaleOf(const std::vector<std::vector<float>>& targets) {
  TargetScale s;
  if (targets.empty()) return s;
  const size_t n = targets[0].size();
  std::vector<double> sum(n, 0), sum2(n, 0);
  for (const auto& row : targets) {
    if (row.size() != n) throw std::invalid_argument("ScaleOf: rows of different lengths");
    for (size_t i = 0; i < n; ++i) {
      sum[i] += row[i];
      sum2[i] += static_cast<double>(row[i]) * row[i];
    }
  }
  for (size_t i = 0; i < n; ++i) {
    const double mean = sum[i] / targets.size(), var = sum2[i] / targets.size() - mean * mean;
    s.mean.push_back(static_cast<float>(mean));
    s.std.push_back(var > 1e-12 ? static_cast<float>(std::sqrt(var)) : 1.0f);
  }
  return s;
}

}  // namespace clothwind::learn
