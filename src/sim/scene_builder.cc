#include "sim/scene_builder.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include <Eigen/Geometry>

namespace clothwind::sim {

double DefaultMaxEdge(const SceneRemeshing& remeshing) {
  if (!remeshing.present) return 0.0;
  // Never below the scene's own smallest size: for [0.3, 0.5] m, 0.4 size_max split to 0.2 m,
  // finer than ArcSim itself refines.
  return std::max(0.4 * remeshing.size_max, remeshing.size_min);
}

double DefaultUniformEdge(const SceneRemeshing& remeshing) {
  if (!remeshing.present) return 0.0;
  return remeshing.size_max;
}

Eigen::MatrixX3d ApplyTransform(const SceneTransform& t, const Eigen::MatrixX3d& V) {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (t.rotate_deg != 0.0) {
    R = Eigen::AngleAxisd(t.rotate_deg * M_PI / 180.0, t.rotate_axis.normalized()).toRotationMatrix();
  }
  Eigen::MatrixX3d out = (t.scale * V) * R.transpose();
  out.rowwise() += t.translate.transpose();
  return out;
}

Eigen::MatrixX3d RigidVelocities(const SceneVelocity& velocity, const Eigen::MatrixX3d& V) {
  Eigen::MatrixX3d out(V.rows(), 3);
  for (Eigen::Index i = 0; i < V.rows(); ++i) {
    const Eigen::Vector3d r = V.row(i).transpose() - velocity.origin;
    out.row(i) = (velocity.linear + velocity.angular.cross(r)).transpose();
  }
  return out;
}

ClothSimulator StartClothSimulator(const ClothSetup& cloth, const Material& material, const SimOptions& options,
                                   std::shared_ptr<const WindField> wind) {
  ClothSimulator sim(cloth.mesh, material, options, std::move(wind));
  // Only when moving: a still start is the constructor's own, bit for bit.
  if (cloth.velocities.rows() == cloth.mesh.V.rows() && !cloth.velocities.isZero(0))
    sim.SetState(cloth.mesh.V, cloth.velocities);
  return sim;
}

SceneSetup BuildScene(const Scene& scene, const BuildOptions& options) {
  if (options.frame_steps < 0) throw std::invalid_argument("BuildOptions.frame_steps must be >= 0");
  // NaN and negative lengths used to fall through the "> 0" tests below as "the scene's default".
  for (const auto& [name, value] : {std::pair{"max_edge", options.max_edge}, std::pair{"split_edge", options.split_edge}})
    if (!(std::isfinite(value) && value >= 0))
      throw std::invalid_argument(std::string("BuildOptions.") + name + " must be a finite length >= 0 m (0: the "
                                  "scene's default), got " + std::to_string(value));
  SceneSetup setup;
  setup.scene = scene;
  if (options.frame_steps > 0) setup.scene.frame_steps = options.frame_steps;
  setup.wind = scene.wind;
  auto fail = [&](const std::string& key, const std::string& what) {
    throw std::runtime_error(scene.path + ": " + key + ": " + what);
  };
  for (size_t c = 0; c < scene.cloths.size(); ++c) {
    const SceneCloth& sc = scene.cloths[c];
    const std::string key = "cloths[" + std::to_string(c) + "]";
    ClothSetup cloth;
    Mesh mesh;
    try {
      mesh = ReadObj(sc.mesh);
    } catch (const std::exception& e) {
      fail(key + ".mesh", e.what());
    }
    // Rest coordinates scale with the cloth so a scaled cloth starts unstressed.
    mesh.U *= sc.transform.scale;
    mesh.V = ApplyTransform(sc.transform, mesh.V);
    // Within 100 m of the origin, where the crossing resolver's single-precision padding holds
    // (crossing_resolver.h): a transform scaling by 1e308 was blamed on the OBJ's vertices, by a
    // number one below the OBJ's, and one by 1e300 read as a degenerate face.
    if (mesh.V.rows() > 0) {
      Eigen::Index row = 0;
      const double farthest = mesh.V.cwiseAbs().rowwise().maxCoeff().maxCoeff(&row);
      if (!(farthest <= kMaxSceneCoordinate)) {
        const bool moved = sc.transform.scale != 1.0 || sc.transform.rotate_deg != 0.0 || !sc.transform.translate.isZero();
        std::ostringstream what;
        what << (moved ? "the transform puts" : "the mesh has") << " a vertex at (" << mesh.V(row, 0) << ", "
             << mesh.V(row, 1) << ", " << mesh.V(row, 2) << "), expected every coordinate within +-"
             << kMaxSceneCoordinate << " m of the origin";
        fail(key + (moved ? ".transform" : ".mesh"), what.str());
      }
    }
    try {
      ValidateMesh(mesh, sc.mesh);
    } catch (const std::exception& e) {
      fail(key + ".mesh", e.what());
    }
    // The rest shape is the OBJ's vt read in metres (ArcSim's rule), not texture coordinates in
    // 0..1 as most exporters write them: such a cloth starts stretched many times over and ran
    // silently, 70 times slower, as something else (a 6 m^2 flag at rest over 1 m^2).
    const double area = SurfaceArea(mesh), rest_area = RestArea(mesh);
    const double stretch = area / rest_area;
    if (!(stretch >= 1.0 / kMaxInitialAreaRatio && stretch <= kMaxInitialAreaRatio)) {
      char what[512];
      std::snprintf(what, sizeof what,
                    "the cloth's area (%.4g m^2 after the transform) is %.3g times its rest area (%.4g m^2): "
                    "the rest shape is the OBJ's vt in metres, or without vt the x, y of its positions "
                    "(ArcSim's rule), so vt written as texture coordinates in 0..1, or a cloth modelled "
                    "steeply out of its x-y plane, start stretched; expected a ratio in [%.2g, %.2g]",
                    area, stretch, rest_area, 1.0 / kMaxInitialAreaRatio, kMaxInitialAreaRatio);
      fail(key + ".mesh", sc.mesh + ": " + what);
    }
    cloth.original_vertices = static_cast<int>(mesh.V.rows());
    const double uniform = options.max_edge > 0 ? options.max_edge : DefaultUniformEdge(sc.remeshing);
    const double split = options.split_edge > 0 ? options.split_edge
                         : options.max_edge > 0 ? 0.0
                                                : DefaultMaxEdge(sc.remeshing);
    try {
      if (uniform > 0) mesh = RefineMesh(mesh, uniform);
      if (split > 0) mesh = SplitLongEdges(mesh, split);
    } catch (const std::exception& e) {
      fail(key + ".remeshing", e.what());
    }
    cloth.max_edge = uniform > 0 && split > 0 ? std::min(uniform, split) : std::max(uniform, split);
    cloth.mesh = std::move(mesh);

    const SceneMaterial& sm = sc.materials.front();
    MaterialMultipliers mult;
    mult.density = sm.density_mult;
    mult.stretching = sm.stretching_mult;
    mult.bending = sm.bending_mult;
    mult.thicken = sm.thicken;
    mult.damping = sm.damping;
    try {
      cloth.material = LoadArcSimMaterial(sm.data, mult);
    } catch (const std::exception& e) {
      fail(key + ".materials[0].data", e.what());
    }

    SimOptions& o = cloth.options;
    o.dt = setup.scene.time_step();
    o.gravity = scene.gravity;
    o.wind_density = scene.wind.density;
    o.wind_drag = scene.wind.drag;
    if (sm.has_strain_limits) {
      o.strain_min = sm.strain_min;
      o.strain_max = sm.strain_max;
    }
    o.repulsion_thickness = scene.magic.repulsion_thickness;
    o.collision_stiffness = scene.magic.collision_stiffness;
    o.self_collision = scene.self_collision;
    if (!scene.crossing_correction) o.crossing_sweeps = 0;
    // After refinement, so new vertices move with the cloth as ArcSim's remeshed nodes do.
    cloth.velocities = RigidVelocities(sc.velocity, cloth.mesh.V);
    setup.cloths.push_back(std::move(cloth));
  }
  // Handles index the ORIGINAL mesh; RefineMesh keeps original vertices first, so the indices
  // stay valid after refinement.
  for (size_t h = 0; h < scene.handles.size(); ++h) {
    const SceneHandle& sh = scene.handles[h];
    ClothSetup& cloth = setup.cloths[sh.cloth];
    for (size_t i = 0; i < sh.nodes.size(); ++i) {
      const int n = sh.nodes[i];
      if (n >= cloth.original_vertices) {
        fail("handles[" + std::to_string(h) + "].nodes[" + std::to_string(i) + "]",
             "node " + std::to_string(n) + " out of range: cloth " + std::to_string(sh.cloth) +
                 "'s mesh has " + std::to_string(cloth.original_vertices) + " nodes");
      }
      cloth.options.handles.push_back(n);
    }
  }
  // After the handles: pinned nodes start still (SetState), so their speed does not count (a spin
  // about a far pinned corner was refused for the corner's speed).
  for (size_t c = 0; c < setup.cloths.size(); ++c) {
    ClothSetup& cloth = setup.cloths[c];
    for (int n : cloth.options.handles) cloth.velocities.row(n).setZero();
    if (cloth.velocities.rows() == 0) continue;
    Eigen::Index row = 0;
    const double fastest = cloth.velocities.rowwise().norm().maxCoeff(&row);
    if (!(fastest <= cloth.options.max_speed)) {
      std::ostringstream what;
      what << "starts vertex " << row << " at " << fastest << " m/s, expected at most the simulator's "
           << cloth.options.max_speed << " m/s (the angular velocity times the distance from the origin counts)";
      fail("cloths[" + std::to_string(c) + "].velocity", what.str());
    }
  }
  return setup;
}

}  // namespace clothwind::sim
