#ifndef CLOTHWIND_SIM_SCENE_BUILDER_H_
#define CLOTHWIND_SIM_SCENE_BUILDER_H_

#include <string>
#include <vector>

#include "sim/cloth_simulator.h"
#include "sim/material.h"
#include "sim/mesh.h"
#include "sim/scene.h"
#include "sim/wind_spec.h"

namespace clothwind::sim {

// One cloth ready to simulate: its mesh transformed into the world and refined, its material
// loaded with the scene's multipliers, and the simulator settings the scene implies.
struct ClothSetup {
  Mesh mesh;          // world positions, rest coordinates, faces (refined)
  Material material;  // multipliers applied
  SimOptions options; // dt, gravity, wind density/drag, handles (refined indices), limits, magic
  // #V by 3 initial velocities [m/s] (ArcSim's cloths[i].velocity, at the refined vertices);
  // zero when the scene gives none, and for pinned nodes (they start still). Start a simulator
  // with StartClothSimulator (below) so they are used.
  Eigen::MatrixX3d velocities;
  int original_vertices = 0;  // #V of the OBJ before refinement (handles index these)
  double max_edge = 0.0;      // longest edge the mesh was refined to [m] (0: not refined)
};

// A scene loaded from disk once, so that many simulations (threads, parameter vectors) can share
// it without touching files again. Plain data: callers may edit it (e.g. wind) before simulating.
struct SceneSetup {
  Scene scene;
  std::vector<ClothSetup> cloths;
  WindSpec wind;  // the scene's wind (copied from scene.wind; edit this one)
};

struct BuildOptions {
  // Longest edge after uniform (RefineMesh, 1-to-4) refinement [m]; no remeshing block: none.
  // 0: the scene's default resolution (DefaultMaxEdge): uniform refinement to size_max, then
  // only the edges still longer than 0.4 size_max are split (SplitLongEdges). Why: ArcSim keeps
  // flat, slowly moving cloth at the upper size and refines only where curvature and velocity
  // demand; a static mesh must resolve the flapping wave everywhere, whose wavelength on a 3 m
  // flag at 10 m/s is ~2.5-3 m, so every edge <= 0.4 size_max (0.2 m for the flag's [0.02, 0.5]
  // m) gives >= 12 edges per wavelength; splitting only the long edges of ArcSim's irregular
  // flag.obj gets there with 485 vertices, where uniform refinement to 0.25 m needs 811. At that
  // resolution the ArcSim flag's droop and flapping match ArcSim's (flag_behaviour_test,
  // docs/scenes.md), ~8x faster than real time on one core. (max_edge 0.25 reproduces the
  // former 811-vertex default.)
  double max_edge = 0.0;
  // Time steps per frame; 0: the scene's frame_steps. Fewer steps are cheaper but damp the
  // flapping (ArcSim's flag at 10 m/s: ~1.4 Hz with 8 steps of 5 ms, ~0.9 Hz with 2 of 20 ms).
  int frame_steps = 0;
  // > 0: after the uniform refinement, split only the edges still longer than this [m]
  // (SplitLongEdges); with max_edge 0 it replaces the default's 0.4 size_max. 0: off (default).
  double split_edge = 0.0;
};

// A cloth's area after the scene transform over its rest area (the OBJ's vt in metres) beyond
// this ratio, or below its inverse, is refused: a cloth starts near its rest shape, and vt
// written as texture coordinates in 0..1 make it start stretched many times over.
constexpr double kMaxInitialAreaRatio = 2.0;

// A cloth's vertices after the scene transform lie within this many metres of the origin on
// every axis: the crossing resolver's single-precision padding holds there (crossing_resolver.h).
constexpr double kMaxSceneCoordinate = 100.0;

// Loads meshes and materials and derives simulator settings.
// Inputs:
//   scene    parsed scene (LoadScene)
//   options  resolution
// Returns the setup. Throws std::runtime_error naming the scene file and the key (e.g.
// "cloths[0].mesh", "handles[0].nodes[1]") when a mesh or material cannot be read or is invalid
// (degenerate triangles, NaN, faces oriented inconsistently, unused vertices, an area more than
// kMaxInitialAreaRatio from the rest area, a vertex beyond kMaxSceneCoordinate, named under
// ".transform" when the transform put it there), an initial velocity that moves a node faster
// than the simulator's max_speed (".velocity"), or a handle node is out of range.
SceneSetup BuildScene(const Scene& scene, const BuildOptions& options = {});

// The default resolution BuildScene picks for a remeshing block (see BuildOptions::max_edge):
// the longest edge [m], 0.4 size_max but at least size_min (0 without a remeshing block). The mesh is first refined
// uniformly to DefaultUniformEdge (size_max), then its longer edges are split.
double DefaultMaxEdge(const SceneRemeshing& remeshing);
double DefaultUniformEdge(const SceneRemeshing& remeshing);

// Node velocities of a rigid motion: linear + angular x (x - origin), ArcSim's apply_velocity.
// Inputs: velocity (SceneVelocity), V #V by 3 positions [m]. Returns #V by 3 velocities [m/s].
Eigen::MatrixX3d RigidVelocities(const SceneVelocity& velocity, const Eigen::MatrixX3d& V);

// A simulator for `cloth` started as the scene says: at the mesh's positions, moving at
// cloth.velocities (why not the constructor alone: it starts every cloth still, and ArcSim's
// cloths[i].velocity was silently dropped). `material` and `options` are the cloth's own unless
// the caller changed them (theta, wind); `wind` as ClothSimulator's.
ClothSimulator StartClothSimulator(const ClothSetup& cloth, const Material& material, const SimOptions& options,
                                   std::shared_ptr<const WindField> wind);

// Applies a scene transform to positions: x -> translate + R(rotate) (scale x).
// Inputs: V #V by 3 [m]. Returns #V by 3 [m].
Eigen::MatrixX3d ApplyTransform(const SceneTransform& transform, const Eigen::MatrixX3d& V);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_SCENE_BUILDER_H_
