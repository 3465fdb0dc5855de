#ifndef CLOTHWIND_DATA_RENDERED_FLAG_GENERATOR_H_
#define CLOTHWIND_DATA_RENDERED_FLAG_GENERATOR_H_

#include <memory>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "data/anemometer_model.h"
#include "data/session_wind.h"
#include "render/render_params.h"
#include "render/renderer.h"
#include "sensors/synthetic_session.h"
#include "sim/cloth_simulator.h"
#include "sim/turbulent_wind.h"

namespace clothwind::data {

// Settings of a rendered field session (`clothwind make-session --frames rendered`).
struct RenderedSessionOptions {
  std::string scene;         // flag scene; "" = DefaultScenePath(flag)
  double max_edge = 0.0;     // mesh resolution [m]; 0 = the scene's default
  double warmup = 5.0;       // simulated before the session starts [s] (the start-up transient)
  uint64_t zeta_seed = 1;    // sun, sky, backdrop, flag design (SampleRenderParams)
  int samples = 2;           // anti-aliasing samples per pixel
  int threads = 0;           // render threads (0: all cores)
  // The field camera: on a tripod, looking at the flag's centre, with the field of view of the
  // session's camera_info (make-session: 60 deg across the width).
  double camera_radius = 6.0;     // [m] horizontal distance from the flag's centre
  double camera_height = 1.6;     // [m]
  double camera_angle_deg = 0.0;  // [deg] off the side-on view
  double camera_fov_deg = 60.0;   // [deg] across the width
  // Spatial turbulence on top of the session's wind history (so flag and anemometer differ).
  sim::TurbulenceParams turbulence{0.1, 20.0, {1.0, 0.8, 0.5}, 128, 0};
  // The anemometer: 2 m beside the pole (away from the camera) at the flag's mid height.
  AnemometerModelParams anemometer{Eigen::Vector3d(0.0, 2.0, 1.0)};
};

// Frames of a field session drawn by simulating the flag in the session's wind and rendering
// it (sensors::FlagFrameGenerator, so sensors::SyntheticSession uses it like the procedural
// one). The simulation is streamed: each Render advances one ClothSimulator to the requested
// time (interpolating positions between its time steps), so sessions of any length fit in
// memory. Frames must therefore be requested in non-decreasing time (as a recording is made).
//
// The wind field (field()) is the one the anemometer model samples too, so the bag's frames and
// sentences come from one wind.
class RenderedFlagGenerator : public sensors::FlagFrameGenerator {
 public:
  // Inputs: session  the session's options (duration, seed, wind, image size); options.
  // Throws std::runtime_error when the scene cannot be loaded, std::invalid_argument on bad ζ.
  RenderedFlagGenerator(const sensors::SyntheticSessionOptions& session,
                        const RenderedSessionOptions& options);
  ~RenderedFlagGenerator() override;

  // The frame at session time t [s]; `wind` must be the session's (it is recomputed from the
  // same options here). Throws std::logic_error if t is earlier than the previous call's, and
  // std::invalid_argument if width/height differ from the session's.
  cv::Mat Render(double t, const sensors::SyntheticWind& wind, int width, int height) const override;

  // The wind in session time (t = 0 at the session start), simulator frame.
  std::shared_ptr<const sim::WindField> field() const { return field_; }
  const render::RenderParams& zeta() const { return zeta_; }
  int num_vertices() const;

  // The anemometer's sentences for the session (SimulateAnemometer on field()).
  std::vector<sensors::SyntheticReading> AnemometerReadings() const;

 private:
  sensors::SyntheticSessionOptions session_;
  RenderedSessionOptions options_;
  render::RenderParams zeta_;
  std::shared_ptr<const sim::WindField> field_;
  Eigen::MatrixXi F_;
  Eigen::MatrixXd UV_;
  // Streaming state (Render is const for the interface; frames come one at a time).
  mutable std::unique_ptr<sim::ClothSimulator> sim_;
  mutable std::unique_ptr<render::Renderer> renderer_;
  mutable Eigen::MatrixX3d previous_;  // positions one step before the current
  mutable double last_t_ = -1e300;
};

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_RENDERED_FLAG_GENERATOR_H_
