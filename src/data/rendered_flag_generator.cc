#include "data/rendered_flag_generator.h"

#include <cstdio>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "data/cloth_animation.h"
#include "data/paths.h"
#include "common/random.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"

namespace clothwind::data {

RenderedFlagGenerator::RenderedFlagGenerator(const sensors::SyntheticSessionOptions& session,
                                             const RenderedSessionOptions& options)
    : session_(session), options_(options) {
  if (!(options.warmup >= 0 && options.warmup <= 3600))  // 1e8 s simulated for hours
    throw std::invalid_argument("rendered session: --warmup must be in 0..3600 s, got " + std::to_string(options.warmup));
  // ζ: the dataset's flag scene sampling (sun, sky, backdrop, design), seen by the field camera.
  zeta_ = render::SampleRenderParams(render::SceneKind::kFlag, options.zeta_seed);
  zeta_.camera_radius = options.camera_radius;
  zeta_.camera_height = options.camera_height;
  zeta_.camera_angle_deg = options.camera_angle_deg;
  zeta_.camera_fov_deg = options.camera_fov_deg;
  zeta_.samples = options.samples;
  zeta_.width = session.width;
  zeta_.height = session.height;
  zeta_.fps = session.fps;
  try {
    render::ValidateRenderParams(zeta_);
  } catch (const std::invalid_argument& e) {
    // Named after the option the user gave: "field 'camera_radius'" names no option of make-session.
    const std::string what = e.what();
    for (const auto& [field, option] : {std::pair<const char*, const char*>{"'width' x 'height'", "--width x --height"},
                                        {"'camera_radius'", "--camera-distance"},
                                        {"'samples'", "--render-samples"},
                                        {"'width'", "--width"},
                                        {"'height'", "--height"},
                                        {"'fps'", "--fps"}})
      if (what.find(field) != std::string::npos)
        throw std::invalid_argument("rendered session: " + std::string(option) + ": " + what);
    throw;
  }

  sim::TurbulenceParams turbulence = options.turbulence;
  turbulence.seed = HashSeed(session.seed, 0x7e4b);
  field_ = std::make_shared<SessionWindField>(std::make_shared<sensors::SyntheticWind>(session),
                                              session.direction_from, turbulence,
                                              std::max(session.wind_base, 0.5));

  const std::string scene_path = options.scene.empty() ? DefaultScenePath(render::SceneKind::kFlag) : options.scene;
  sim::BuildOptions build;
  build.max_edge = options.max_edge;
  const sim::SceneSetup setup = sim::BuildScene(sim::LoadScene(scene_path, [](const std::string& w) {
    std::fprintf(stderr, "rendered flag: warning: %s\n", w.c_str());
  }), build);
  const sim::ClothSetup& cloth = setup.cloths.at(0);
  F_ = cloth.mesh.F;
  const Eigen::MatrixXd U = cloth.mesh.U;
  UV_ = NormalizeTextureCoordinates(U, U.colwise().minCoeff().transpose(), U.colwise().maxCoeff().transpose());
  // The simulator's clock starts `warmup` before the session does.
  sim_ = std::make_unique<sim::ClothSimulator>(sim::StartClothSimulator(
      cloth, cloth.material, cloth.options, std::make_shared<TimeShiftedWind>(field_, -options.warmup)));
  previous_ = sim_->positions();
  render::RenderOptions ro;
  ro.threads = options.threads;
  renderer_ = std::make_unique<render::Renderer>(zeta_, ro);
}

RenderedFlagGenerator::~RenderedFlagGenerator() = default;

int RenderedFlagGenerator::num_vertices() const { return static_cast<int>(UV_.rows()); }

cv::Mat RenderedFlagGenerator::Render(double t, const sensors::SyntheticWind& /*wind*/, int width,
                                      int height) const {
  if (width != zeta_.width || height != zeta_.height)
    throw std::invalid_argument("rendered session: frame size " + std::to_string(width) + "x" +
                                std::to_string(height) + " differs from the session's " +
                                std::to_string(zeta_.width) + "x" + std::to_string(zeta_.height));
  if (t < last_t_)
    throw std::logic_error("rendered session: frames must be drawn in time order (" + std::to_string(t) +
                           " s after " + std::to_string(last_t_) + " s)");
  last_t_ = t;
  const double target = t + options_.warmup;  // simulator time
  const double dt = sim_->options().dt;
  try {
    while (sim_->time() < target) {
      previous_ = sim_->positions();
      sim_->Step();
    }
  } catch (const std::runtime_error& e) {  // the simulator's blow-up check: name the frame
    throw std::runtime_error("rendered session: frame at session time " + std::to_string(t) + " s (simulator time " +
                             std::to_string(target) + " s, warm-up included): " + e.what());
  }
  const Eigen::MatrixX3d& current = sim_->positions();
  if (!current.allFinite()) throw std::runtime_error("rendered session: the flag simulation diverged");
  // Positions at exactly the capture time, between the last two steps.
  const double w = sim_->time() > 0 ? std::clamp(1.0 - (sim_->time() - target) / dt, 0.0, 1.0) : 1.0;
  const Eigen::MatrixXd V = (1.0 - w) * previous_ + w * current;
  return renderer_->RenderFrame(V, F_, UV_);
}

std::vector<sensors::SyntheticReading> RenderedFlagGenerator::AnemometerReadings() const {
  AnemometerModelParams p = options_.anemometer;
  p.rate = session_.anemometer_rate;
  p.latency = session_.anemometer_latency;
  p.direction_from = session_.direction_from;
  p.seed = HashSeed(session_.seed, 0xa7e);
  return SimulateAnemometer(*field_, p, session_.start_time, session_.duration);
}

}  // namespace clothwind::data
