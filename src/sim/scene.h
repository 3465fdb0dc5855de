#ifndef CLOTHWIND_SIM_SCENE_H_
#define CLOTHWIND_SIM_SCENE_H_

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "sim/wind_spec.h"

namespace clothwind::sim {

// An ArcSim scene file, parsed but not yet loaded (meshes and materials stay paths, resolved
// to absolute paths that exist). See docs/scenes.md for the keys, defaults and path rules.

// `transform` of a cloth: x_world = translate + R(rotate) * (scale * x_obj).
struct SceneTransform {
  Eigen::Vector3d translate = Eigen::Vector3d::Zero();  // [m]
  double rotate_deg = 0.0;                              // angle [deg] about rotate_axis
  Eigen::Vector3d rotate_axis = Eigen::Vector3d::UnitZ();  // need not be unit length
  double scale = 1.0;                                   // uniform scale [-]
};

// One entry of a cloth's `materials`.
struct SceneMaterial {
  std::string data;                  // absolute path of the material JSON
  double thicken = 1.0;              // number of layers: scales density, stretching, bending
  double density_mult = 1.0;
  double stretching_mult = 1.0;
  double bending_mult = 1.0;
  double damping = 0.0;              // stiffness-proportional damping [s]
  double strain_min = -1.0;          // strain_limits[0]; < 0: no limit
  double strain_max = -1.0;          // strain_limits[1]; < 0: no limit
  bool has_strain_limits = false;
};

// A cloth's `remeshing` block. ArcSim remeshes adaptively between size[0] and size[1]; we
// refine once, statically (docs/scenes.md says why and which edge length we choose).
struct SceneRemeshing {
  double refine_angle = 0.3;
  double refine_compression = 0.01;
  double refine_velocity = 1.0;
  double size_min = 0.0;  // [m]; 0: no remeshing block given
  double size_max = 0.0;  // [m]
  double aspect_min = 0.2;
  bool present = false;
};

// ArcSim's `cloths[i].velocity`: every node starts at linear + angular x (x - origin), x its
// position after the transform (ArcSim's apply_velocity).
struct SceneVelocity {
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();   // [m/s]
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();  // [rad/s], about `origin`
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // [m], world
};

struct SceneCloth {
  std::string mesh;  // absolute path of the OBJ
  SceneTransform transform;
  SceneVelocity velocity;
  std::vector<SceneMaterial> materials;
  SceneRemeshing remeshing;
};

// A `handles` entry: nodes (indices into the ORIGINAL mesh of cloth `cloth`) held in place.
struct SceneHandle {
  int cloth = 0;
  std::vector<int> nodes;
  int motion = -1;       // index into motions, -1: fixed
  double start_time = 0.0;
  double end_time = 1e300;
};

struct SceneMagic {
  double repulsion_thickness = 1e-3;  // [m] ArcSim's default
  double collision_stiffness = 1e9;   // ArcSim's default
};

struct Scene {
  std::string path;        // absolute path of the scene file
  double frame_time = 0.04;  // [s]
  int frame_steps = 1;       // time steps per frame
  double duration = 20.0;    // [s] `end_time` or `end_frame` x frame_time (the first reached, as
                             // ArcSim), else `duration` (ArcSim's end in the `timestep` form)
  // ArcSim's `disable` list: "proximity" turns the vertex-face repulsion (and with it the crossing
  // correction) off, "collision" the crossing correction; "strainlimiting" and "remeshing" clear
  // the cloths' strain limits and remeshing blocks when parsed.
  bool self_collision = true;
  bool crossing_correction = true;
  std::vector<SceneCloth> cloths;
  std::vector<SceneHandle> handles;
  std::vector<nlohmann::json> motions;  // kept as given; only fixed handles are simulated
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();  // [m/s^2]
  WindSpec wind;
  SceneMagic magic;

  double time_step() const { return frame_time / frame_steps; }
};

// Receives warnings (unknown keys, ignored features). Default: print to stderr.
using WarningSink = std::function<void(const std::string&)>;

// Reads an ArcSim scene file (comments allowed).
//
// Inputs:
//   path  scene JSON file
//   warn  where warnings go (empty: stderr)
// Returns the parsed scene, paths made absolute.
// Throws std::runtime_error naming the file and the JSON path of the offending key
// (e.g. "cloths[0].materials[0].data") for wrong types, non-finite or out-of-range numbers,
// and files that cannot be found.
Scene LoadScene(const std::string& path, const WarningSink& warn = {});

// The same from text already in memory; `path` is used for messages and to resolve paths.
Scene ParseScene(const std::string& text, const std::string& path, const WarningSink& warn = {});

// Resolves a path written in a scene the way ArcSim users expect: absolute paths as they are;
// relative ones first next to the scene file, then in the scene folder's parent (ArcSim's
// root, where `conf/` and `meshes/` are siblings), then in the working directory.
// Returns the first that is a file (a folder does not count), or "" if none is.
std::string ResolveScenePath(const std::string& scene_path, const std::string& relative);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_SCENE_H_
