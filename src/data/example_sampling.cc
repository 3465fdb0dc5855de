#include "data/example_sampling.h"

#include <cmath>
#include <stdexcept>

#include "common/formatted.h"
#include "common/random.h"

namespace clothwind::data {
namespace {

// Streams of one simulation's randomness (HashSeed(seed, stream)), kept apart so that adding a
// draw to one part never shifts another.
enum Stream : uint64_t { kTheta = 1, kWind = 2, kFabric = 3, kSplit = 4, kView = 5, kCamera = 6 };

double LogUniform(Rng& rng, double factor) {
  if (factor <= 1.0) {
    rng.Uniform();  // a draw all the same, so the later draws of the stream stay where they were
    return 1.0;
  }
  const double l = std::log(factor);
  return std::exp(rng.Uniform(-l, l));
}

}  // namespace

void ValidateRanges(const SamplingRanges& r) {
  if (!(r.wind_min >= 0 && r.wind_max >= r.wind_min && std::isfinite(r.wind_max)))
    throw std::invalid_argument(
        "sampling ranges: expected 0 <= wind_min <= wind_max, finite [m/s] (--wind-min, --wind-max), got " +
        FormattedNumber(r.wind_min) + ", " + FormattedNumber(r.wind_max));
  if (!(r.cloth_area_weight_min > 0 && r.cloth_area_weight_max >= r.cloth_area_weight_min &&
        std::isfinite(r.cloth_area_weight_max)))
    throw std::invalid_argument("sampling ranges: expected 0 < cloth area weight min <= max, finite");
  if (!(r.area_weight_factor >= 1 && r.bending_factor >= 1 && r.bending_jitter >= 1 &&
        std::isfinite(r.area_weight_factor) && std::isfinite(r.bending_factor) && std::isfinite(r.bending_jitter)))
    throw std::invalid_argument("sampling ranges: perturbation factors must be finite and >= 1");
  render::ValidateCameraRanges(r.camera);
}

std::vector<std::string> CameraRangeWarnings(const render::CameraRanges& camera, double cloth_length,
                                             double centre_height, int frame_px) {
  std::vector<std::string> warnings;
  if (!(cloth_length > 0) || frame_px <= 0) return warnings;
  constexpr double kFovDeg = 45.0;  // SampleRenderParams' field of view
  constexpr double kMinFraction = 0.05;
  const double rise = std::max(std::abs(camera.height_max - centre_height), std::abs(camera.height_min - centre_height));
  const double farthest = std::hypot(camera.radius_max, rise);
  const double fraction = cloth_length / (2.0 * farthest * std::tan(kFovDeg / 2 * M_PI / 180.0));
  if (fraction < kMinFraction)
    warnings.push_back("cameras up to " + Formatted("%.4g", farthest) + " m away (--camera-radius, --camera-height) see "
                       "the " + FormattedNumber(cloth_length) + " m cloth over about " +
                       Formatted("%.3g", fraction * frame_px) + " px of the " + std::to_string(frame_px) +
                       " px frame at most: clips show next to nothing of it");
  // The radius is measured from the cloth's centre, so its far end reaches half its length from it.
  if (camera.radius_min < cloth_length / 2)
    warnings.push_back("cameras from " + FormattedNumber(camera.radius_min) + " m from the cloth's centre "
                       "(--camera-radius) stand within half its length (" + FormattedNumber(cloth_length) +
                       " m): it overflows the frame, and clips show little of it");
  return warnings;
}

SamplingRanges DefaultRanges(render::SceneKind kind) {
  SamplingRanges r;
  if (kind == render::SceneKind::kCloth) r.wind_max = 5.0;
  r.camera = render::TableTwoCameraRanges(kind);
  return r;
}

uint64_t SimulationSeed(uint64_t global_seed, int64_t index) {
  if (index < 0) throw std::invalid_argument("simulation index must be >= 0");
  return HashSeed(global_seed, static_cast<uint64_t>(index), 0x5eedda7aULL);
}

SimulationSample SampleFlagSimulation(const sim::Theta& base, uint64_t global_seed, int64_t index,
                                      const SamplingRanges& ranges) {
  ValidateRanges(ranges);
  SimulationSample s;
  s.index = index;
  s.seed = SimulationSeed(global_seed, index);
  s.fabric = "camel-ponte-roma";
  Rng rng(HashSeed(s.seed, kTheta));
  s.theta = base;
  s.theta[sim::kAreaWeightIndex] = base[sim::kAreaWeightIndex] * LogUniform(rng, ranges.area_weight_factor);
  const double stiffness = LogUniform(rng, ranges.bending_factor);
  for (int k = 0; k < 15; ++k)
    s.theta[sim::kBendingIndex + k] = base[sim::kBendingIndex + k] * stiffness * LogUniform(rng, ranges.bending_jitter);
  Rng wind(HashSeed(s.seed, kWind));
  s.theta[sim::kWindSpeedIndex] = wind.Uniform(ranges.wind_min, ranges.wind_max);
  s.wind_velocity = Eigen::Vector3d(s.theta[sim::kWindSpeedIndex], 0, 0);
  return s;
}

SimulationSample SampleClothSimulation(const std::vector<Fabric>& fabrics, uint64_t global_seed,
                                       int64_t index, const SamplingRanges& ranges) {
  ValidateRanges(ranges);
  if (fabrics.empty()) throw std::invalid_argument("ClothSim needs at least one fabric");
  SimulationSample s;
  s.index = index;
  s.seed = SimulationSeed(global_seed, index);
  Rng pick(HashSeed(s.seed, kFabric));
  s.fabric_index = pick.UniformInt(static_cast<int>(fabrics.size()));
  const Fabric& f = fabrics[s.fabric_index];
  s.fabric = f.name;
  Rng rng(HashSeed(s.seed, kTheta));
  s.theta[sim::kAreaWeightIndex] = rng.Uniform(ranges.cloth_area_weight_min, ranges.cloth_area_weight_max);
  for (int d = 0; d < 3; ++d)
    for (int c = 0; c < 5; ++c) s.theta[sim::kBendingIndex + 5 * d + c] = f.material.bending[d][c];
  Rng wind(HashSeed(s.seed, kWind));
  const double speed = wind.Uniform(ranges.wind_min, ranges.wind_max);
  s.theta[sim::kWindSpeedIndex] = speed;
  s.wind_velocity = Eigen::Vector3d(speed * std::cos(kClothWindAzimuth), speed * std::sin(kClothWindAzimuth), 0);
  return s;
}

render::RenderParams SampleView(render::SceneKind kind, uint64_t simulation_seed, int view,
                                int views, const std::vector<std::string>& background_images) {
  return SampleView(kind, simulation_seed, view, views, background_images,
                    render::TableTwoCameraRanges(kind));
}

render::RenderParams SampleView(render::SceneKind kind, uint64_t simulation_seed, int view,
                                int views, const std::vector<std::string>& background_images,
                                const render::CameraRanges& camera) {
  if (views < 1 || view < 0 || view >= views)
    throw std::invalid_argument("view " + std::to_string(view) + " of " + std::to_string(views) +
                                ": expected 0 <= view < views");
  render::RenderParams p = render::SampleRenderParams(kind, HashSeed(simulation_seed, kView),
                                                      background_images, camera);
  Rng cam(HashSeed(simulation_seed, kCamera, static_cast<uint64_t>(view)));
  if (view > 0) {  // the same scene seen from elsewhere
    p.camera_height = cam.Uniform(camera.height_min, camera.height_max);
    p.camera_radius = cam.Uniform(camera.radius_min, camera.radius_max);
    p.seed = HashSeed(p.seed, static_cast<uint64_t>(view));
  }
  const double half = camera.angle_max_deg;
  p.camera_angle_deg = -half + 2 * half * (view + cam.Uniform()) / views;
  return p;
}

std::string SplitOf(uint64_t simulation_seed, double val_fraction, double test_fraction) {
  if (!(val_fraction >= 0 && test_fraction >= 0 && val_fraction + test_fraction <= 1))
    throw std::invalid_argument("split fractions: expected val, test >= 0 and val + test <= 1");
  Rng rng(HashSeed(simulation_seed, kSplit));
  const double u = rng.Uniform();
  if (u < test_fraction) return "test";
  if (u < test_fraction + val_fraction) return "val";
  return "train";
}

std::string ExampleName(render::SceneKind kind, int64_t index, int view) {
  char name[64];
  std::snprintf(name, sizeof(name), "%s-%06lld-v%d", render::SceneKindName(kind).c_str(),
                static_cast<long long>(index), view);
  return name;
}

}  // namespace clothwind::data
