#ifndef CLOTHWIND_DATA_EXAMPLE_SAMPLING_H_
#define CLOTHWIND_DATA_EXAMPLE_SAMPLING_H_

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "render/render_params.h"
#include "sim/material.h"
#include "sim/parameters.h"

namespace clothwind::data {

// What a dataset's examples are drawn from: FlagSim (a flag of camel ponte roma with perturbed
// area weight and bending in a steady wind along +x) or ClothSim (a hanging cloth of one of
// several fabrics, area weight over the hanging-cloth study's range, wind on the horizontal
// plane). Every draw follows from (global seed, simulation index) alone, so any machine, shard or
// resumed run draws the same example i.
struct SamplingRanges {
  double wind_min = 0.0;   // θ_e ~ U(wind_min, wind_max) [m/s]
  double wind_max = 10.0;
  // FlagSim: area weight = base × f, f log-uniform in [1/area_weight_factor, area_weight_factor];
  // bending = base × g × h_k, g log-uniform in [1/bending_factor, bending_factor] (overall
  // stiffness) and h_k log-uniform in [1/bending_jitter, bending_jitter] per table entry (shape).
  double area_weight_factor = 2.0;
  double bending_factor = 4.0;
  double bending_jitter = 1.25;
  // ClothSim: area weight ~ U(cloth_area_weight_min, cloth_area_weight_max) [kg/m^2] (Bouman et
  // al.'s fabrics, 0.1-0.4); bending is the fabric's own (the paper keeps it fixed).
  double cloth_area_weight_min = 0.1;
  double cloth_area_weight_max = 0.4;
  // Where the cameras stand (render::CameraRanges; DefaultRanges gives Table 2's of the kind).
  render::CameraRanges camera;
};

// The default ranges of a dataset kind (FlagSim: wind 0-10 m/s; ClothSim: wind 0-5 m/s).
SamplingRanges DefaultRanges(render::SceneKind kind);

// Throws std::invalid_argument naming the range unless 0 <= wind_min <= wind_max, the factors
// are >= 1, the cloth area weights 0 < min <= max and the cameras valid (ValidateCameraRanges).
void ValidateRanges(const SamplingRanges& r);

// What the camera ranges would make of a cloth of `cloth_length` metres (its longest rest side)
// whose centre is `centre_height` metres up (render::MeshCentre), in frames of `frame_px`, seen
// through the samplers' 45 deg field of view:
//   - at the farthest camera (its radius and the height farthest from the centre's) it spans
//     under 5 % of the frame: "clips show next to nothing of it";
//   - the nearest radius (from the cloth's centre) is within half its length: the cloth overflows
//     the frame (or passes the camera), and clips show little of it, or of its motion.
// Returns one sentence per finding (none for Table 2's ranges and cloths). Why warnings, not
// refusals: a far or near camera is a legitimate experiment; an unwarned one was not (clips
// without a visible flag, labelled with the wind, went into a dataset without a word).
std::vector<std::string> CameraRangeWarnings(const render::CameraRanges& camera, double cloth_length,
                                             double centre_height, int frame_px);

// One fabric of ClothSim.
struct Fabric {
  std::string name;       // file stem, e.g. "gray-interlock"
  std::string path;       // the ArcSim material JSON
  sim::Material material; // loaded with the scene's multipliers
};

// The simulation behind one or more examples (one per view).
struct SimulationSample {
  int64_t index = 0;         // simulation index in the dataset (0-based)
  uint64_t seed = 0;         // SimulationSeed(global seed, index): wind turbulence, split, ζ
  sim::Theta theta;          // area weight, 15 bending [N m], wind speed [m/s] (parameters.h)
  Eigen::Vector3d wind_velocity = Eigen::Vector3d::Zero();  // mean wind [m/s], |v| = theta[16]
  std::string fabric;        // material name (file stem)
  int fabric_index = 0;      // index into the fabric list (ClothSim), 0 for FlagSim
};

// Seed of simulation `index` of a dataset with seed `global_seed` (a hash of both).
uint64_t SimulationSeed(uint64_t global_seed, int64_t index);

// FlagSim draw: base theta (the flag scene's: camel ponte roma, two layers) perturbed as
// SamplingRanges says, wind along +x (the renderer's flags fly along +x; camera poses give the
// apparent direction).
// Inputs: base  the scene's theta (SceneTheta); global_seed; index >= 0; ranges.
SimulationSample SampleFlagSimulation(const sim::Theta& base, uint64_t global_seed, int64_t index,
                                      const SamplingRanges& ranges);

// The direction of ClothSim's wind [rad, counter-clockwise from +x]: the seed paper's Listing 2
// (velocity [s, s, 0]) and config/scenes/cloth.json. The cloth hangs facing x with the camera on
// -x, so this wind pushes it away from the camera at 45° to its normal, the same way in every
// simulation; the views' camera angles (Table 2's "orientation w.r.t. wind direction") vary what
// the camera sees of it. (Until 2026-12-06 the direction was uniform over the circle: a wind
// along the cloth's plane barely moved it whatever its speed, a third of the clips saw less than
// half the speed across the cloth, and a wind towards the camera blew the cloth at the lens.)
constexpr double kClothWindAzimuth = M_PI / 4;

// ClothSim draw: a fabric (uniform over `fabrics`), area weight from the ranges, the fabric's
// bending, wind speed from the ranges in the direction kClothWindAzimuth.
// Inputs: fabrics  non-empty; global_seed; index >= 0; ranges.
SimulationSample SampleClothSimulation(const std::vector<Fabric>& fabrics, uint64_t global_seed,
                                       int64_t index, const SamplingRanges& ranges);

// Render parameters ζ of view `view` (0..views-1) of a simulation: view 0 draws every ζ from
// the paper's Table 2 ranges (render/render_params.h); the other views keep its scene (sun,
// backdrop, texture) and move the camera: new height and radius, and an angle stratified over
// the Table 2 range (view v of K draws from the v-th of K equal parts of [-15, 15] deg for
// flags, [-5, 5] for cloth) so the views show different apparent wind directions.
// With `camera`, heights, radii and angles are drawn from its ranges instead of Table 2's (the
// angle still stratified, over [-angle_max, angle_max]); every other draw stays the same, so a
// dataset with other cameras shows the same simulations, scenes and textures.
// Inputs: kind; simulation_seed; view in [0, views); views >= 1; background_images (may be
//   empty); camera  (default TableTwoCameraRanges(kind)).
render::RenderParams SampleView(render::SceneKind kind, uint64_t simulation_seed, int view,
                                int views, const std::vector<std::string>& background_images = {});
render::RenderParams SampleView(render::SceneKind kind, uint64_t simulation_seed, int view,
                                int views, const std::vector<std::string>& background_images,
                                const render::CameraRanges& camera);

// Which split a simulation belongs to, from a hash of its seed: "test" with probability
// test_fraction, "val" with val_fraction, else "train". All views of a simulation share it (no
// leak of one simulation across splits); shards and resumed runs agree.
std::string SplitOf(uint64_t simulation_seed, double val_fraction, double test_fraction);

// Folder name of an example: "<kind>-<index, 6 digits>-v<view>", e.g. "flag-000012-v1".
std::string ExampleName(render::SceneKind kind, int64_t index, int view);

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_EXAMPLE_SAMPLING_H_
