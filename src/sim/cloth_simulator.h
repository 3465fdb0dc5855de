#ifndef CLOTHWIND_SIM_CLOTH_SIMULATOR_H_
#define CLOTHWIND_SIM_CLOTH_SIMULATOR_H_

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "sim/material.h"
#include "sim/mesh.h"
#include "sim/strain_limiter.h"
#include "sim/wind_field.h"

namespace clothwind::sim {

// How bending forces enter the time step.
enum class BendingSolve { kAuto, kImplicit, kExplicit };

// Settings of one simulation (an ArcSim scene's numbers; defaults are the flag scene's).
struct SimOptions {
  double dt = 0.005;                                // time step [s] (ArcSim: frame_time/frame_steps)
  Eigen::Vector3d gravity = Eigen::Vector3d(0, 0, -9.8);  // [m/s^2]
  double wind_density = 1.0;                        // ArcSim wind "density" [kg/m^3]
  double wind_drag = 0.0;                           // ArcSim wind "drag" [kg/(m^2 s)]
  std::vector<int> handles;                         // pinned vertex indices (fixed in place)
  // Principal-stretch limits (ArcSim "strain_limits", e.g. 0.95, 1.05); 0 / inf switch a side off.
  double strain_min = 0.0;
  double strain_max = std::numeric_limits<double>::infinity();
  // The limiter's sweeps (strain_limiter.h): at most this many per step, ending once no face is
  // outside the limits by more than the relative tolerance (0: by more than round-off, as before
  // the tolerance existed, so FlagSim's frames stay those of its generator version). Why 4,
  // though they leave 1 % of the flag's faces 8-10 % over the limit: docs/simulator.md,
  // "Strain limiting".
  int strain_limit_iterations = 4;
  double strain_limit_tolerance = 0.0;
  // Sweeps (the default, FlagSim's) or local/global iterations, which strain_limit_iterations
  // then counts, at least 20 (30 and a tolerance of 1e-3 measured; StrainLimitMethod;
  // docs/simulator.md, "Strain limiting").
  StrainLimitMethod strain_limit_method = StrainLimitMethod::kSweeps;
  double repulsion_thickness = 10e-3;               // ArcSim magic.repulsion_thickness [m]
  double collision_stiffness = 1e6;                 // ArcSim magic.collision_stiffness [N/m^3]
                                                    // (times min(node area, face area) per pair)
  bool self_collision = true;                       // vertex-face repulsion on/off
  // With self_collision: passes of the post-step correction that moves vertices that jumped
  // through a face during the step back to their side (crossing_resolver.h); 0 = off.
  int crossing_sweeps = 8;
  // Bending in the implicit solve (ArcSim) or explicit. Cloth bending is so soft next to the
  // node masses that explicit bending is stable by orders of magnitude at these steps, and it
  // saves ~20 % of a step (a hinge's two opposite vertices then need no matrix block). kAuto
  // bounds h^2 lambda_max(M^-1 K_bend) over the hinges (Gershgorin, with the table's largest
  // stiffness) and goes implicit only if that bound exceeds 0.5 (explicit needs < ~4).
  BendingSolve bending_solve = BendingSolve::kAuto;
  double cg_tolerance = 1e-2;                       // relative residual of the linear solve
  int cg_max_iterations = 300;
  // A vertex faster than this [m/s] means the state has exploded (a flag in a 30 m/s gale moves
  // at tens of m/s): Step throws instead of carrying on (see Step).
  double max_speed = 1e3;
};

// Energies of the current state [J].
struct ClothEnergy {
  double kinetic = 0;
  double gravitational = 0;  // -sum m g.x
  double stretching = 0;     // with the stiffness evaluated at the current strain
  double bending = 0;
  double repulsion = 0;      // vertex-face penalty energy (0 without self_collision)
  double Total() const { return kinetic + gravitational + stretching + bending + repulsion; }
};

// What the last step did (for benches and diagnostics).
struct StepStats {
  int cg_iterations = 0;
  double cg_relative_residual = 0;
  int repulsion_pairs = 0;
  int strain_limited_faces = 0;  // faces outside the limits before projection
  int strain_limit_sweeps = 0;   // the limiter's sweeps this step (0: no limits)
  // Largest relative excess over the limits in the limiter's last sweep (StrainLimitResult):
  // above strain_limit_tolerance when it stopped at strain_limit_iterations unconverged.
  double strain_limit_excess = 0;
  bool strain_limit_converged = true;  // the limiter's sweeps ended within tolerance (or no limits)
  int crossings_resolved = 0;    // vertex-face crossings undone after the step
  bool implicit_bending = false;  // what kAuto (or the option) chose
  // Wall time of the phases of the step [s] (steady clock), for benches.
  double seconds_proximity = 0;
  double seconds_forces = 0;
  double seconds_solve = 0;
  double seconds_strain_limit = 0;
};

// ArcSim-style cloth: Wang et al. 2011 anisotropic nonlinear stretching and direction/curvature
// dependent bending (material.h), gravity, ArcSim's explicit wind force, pinned handles,
// vertex-face repulsion, strain limiting, and one Newton step of backward Euler per time step:
//   (M - h (h + gamma) K) dv = h (f + (h + gamma) K v),   x += h (v + dv),
// K the force Jacobian, gamma the material's Rayleigh damping. The mesh is fixed (no adaptive
// remeshing; use RefineMesh for resolution). Instances share nothing: separate instances may run
// concurrently; one instance is not thread-safe. Results are deterministic (serial sums).
class ClothSimulator {
 public:
  // Inputs:
  //   mesh      cloth mesh: V initial world positions [m], F faces, U rest coordinates [m]
  //   material  cloth material (multipliers applied)
  //   options   simulation settings
  //   wind      air velocity field (nullptr = still air)
  // Throws std::invalid_argument on an invalid mesh (ValidateMesh), handles out of range,
  // dt <= 0, or bad options.
  ClothSimulator(Mesh mesh, Material material, SimOptions options,
                 std::shared_ptr<const WindField> wind);
  ~ClothSimulator();
  ClothSimulator(ClothSimulator&&) noexcept;
  ClothSimulator& operator=(ClothSimulator&&) noexcept;

  // Advances the state by one time step options().dt.
  // Throws std::runtime_error, naming the simulated time, the vertex and what went wrong, when
  // the step meets a non-finite force, a linear system beyond double range (a right-hand side
  // whose norm overflows, a non-finite CG residual: the solve would otherwise stop at once and
  // leave the cloth still), or leaves a non-finite position or velocity or a speed above
  // options().max_speed (an exploded simulation: carrying on would only produce garbage, and
  // slowly). The state is then left as the step made it, for diagnostics, and every further
  // Step throws the same error until SetState gives a valid state.
  void Step();

  // Simulated time [s] (steps taken * dt).
  double time() const;

  // #V by 3 current positions [m] / velocities [m/s].
  const Eigen::MatrixX3d& positions() const;
  const Eigen::MatrixX3d& velocities() const;

  // Replaces the state (e.g. to restart from a saved one). Handles stay where the given positions
  // put them. Inputs: #V by 3 positions [m] and velocities [m/s]. Throws on shape mismatch / NaN.
  void SetState(const Eigen::MatrixX3d& positions, const Eigen::MatrixX3d& velocities);

  // Replaces the wind field (nullptr = still air).
  void set_wind(std::shared_ptr<const WindField> wind);

  // The mesh as constructed (F, U, initial V), the material and the options.
  const Mesh& mesh() const;
  const Material& material() const;
  const SimOptions& options() const;

  // #V lumped node masses [kg] (a third of each adjacent face's rest area times density).
  const Eigen::VectorXd& masses() const;

  // Energies of the current state.
  ClothEnergy Energy() const;

  // Total external + internal force on every node at the current state (#V by 3) [N]: for tests
  // and diagnostics (handles included, not zeroed).
  Eigen::MatrixX3d Forces() const;

  // The force Jacobian the implicit step assembles, applied to a displacement: (df/dx) dx at the
  // current state (#V by 3 in, #V by 3 out) [N]. Stretching in its positive-definite form,
  // bending only when implicit (and Gauss-Newton: exact where the hinges are flat), repulsion
  // with its Gauss-Newton blocks. For tests (finite differences of Forces()) and diagnostics.
  Eigen::MatrixX3d ForceJacobianTimes(const Eigen::MatrixX3d& dx) const;

  const StepStats& last_step_stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_CLOTH_SIMULATOR_H_
