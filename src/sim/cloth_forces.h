#ifndef CLOTHWIND_SIM_CLOTH_FORCES_H_
#define CLOTHWIND_SIM_CLOTH_FORCES_H_

#include <Eigen/Core>

namespace clothwind::sim {

// Element-level forces of the cloth model (ArcSim 0.2's physics.cpp, re-derived). Each returns
// the energy, the force f = -dE/dx and the force Jacobian df/dx of one element, so the simulator
// assembles them and the tests check them against finite differences. Vectors stack the element's
// vertex positions x = (x0, x1, x2[, x3]) as 9- or 12-vectors.

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

// Rest data of a triangle.
struct TriangleRest {
  Eigen::Matrix2d Dm_inv;  // inverse of [u1-u0, u2-u0] (2 by 2) [1/m]
  double area = 0;         // material-space area [m^2]
};

// Inputs:
//   u0, u1, u2  material coordinates of the corners [m] (non-degenerate)
// Returns Dm_inv and the rest area.
TriangleRest MakeTriangleRest(const Eigen::Vector2d& u0, const Eigen::Vector2d& u1,
                              const Eigen::Vector2d& u2);

// Deformation gradient F = [x1-x0, x2-x0] Dm_inv (3 by 2) and Green strain G = (F^T F - I)/2.
Eigen::Matrix<double, 3, 2> DeformationGradient(const Vector9d& x, const TriangleRest& rest);
Eigen::Matrix2d GreenStrain(const Vector9d& x, const TriangleRest& rest);

struct StretchingTerms {
  double energy = 0;  // [J]
  Vector9d force;     // [N]
  Matrix9d jacobian;  // [N/m]
};

// Wang et al. stretching of one triangle with the stiffness k = (k11, k12, k22, k33) [N/m] held
// fixed (ArcSim evaluates k from the current strain and differentiates with k constant):
//   E = A/2 (k0 G00^2 + 2 k1 G00 G11 + k2 G11^2 + 2 k3 G01^2).
// Inputs:
//   x         9-vector of corner positions [m]
//   rest      triangle rest data
//   k         stiffness 4-vector [N/m]
//   definite  true: ArcSim's Jacobian (the strain-Hessian terms only where the strain is
//             tensile, max(G,0)), which keeps the system definite; false: the exact Jacobian
// Output: energy, force, Jacobian.
StretchingTerms StretchingForce(const Vector9d& x, const TriangleRest& rest,
                                const Eigen::Vector4d& k, bool definite);

// StretchingForce with the Jacobian written as 3x3 blocks, jacobian[3 i + j] = d f_i / d x_j
// (the simulator's hot path: assembled from four 3x3 outer products instead of 9x9 ones).
// Inputs as StretchingForce. Outputs: force (9-vector) [N], jacobian (9 blocks) [N/m];
// returns the energy [J].
double StretchingForceBlocks(const Vector9d& x, const TriangleRest& rest, const Eigen::Vector4d& k,
                             bool definite, Vector9d* force, Eigen::Matrix3d jacobian[9]);

// Signed dihedral angle of the hinge x0-x1 shared by triangles (x0,x1,x2) and (x1,x0,x3):
//   theta = atan2(e . (n0 x n1), n0 . n1), e = unit(x0 - x1), n0, n1 the unit face normals
// (ArcSim's convention: theta grows as x2 moves along n0), 0 when flat [rad]; optionally its
// gradient (12-vector) w.r.t. (x0, x1, x2, x3) (Bridson et al. 2003), exact except for a sliver
// face: the opposite vertices' heights over the edge enter the gradient bounded below by
// kMinHingeHeight |x0 - x1|, as in ArcSim, so it stays bounded as a face collapses.
constexpr double kMinHingeHeight = 1e-3;
double DihedralAngle(const Vector12d& x, Vector12d* gradient = nullptr);

struct BendingTerms {
  double energy = 0;   // [J]
  Vector12d force;     // [N]
  Matrix12d jacobian;  // [N/m]
};

// ArcSim's bending of one hinge with stiffness ke [N m] held fixed:
//   E = ke * shape * (theta - theta_rest)^2 / 4, shape = l^2 / (2 (A0 + A1)),
// l the rest edge length and A0, A1 the rest areas (Grinspun et al. / Bridson et al. weighting).
// The Jacobian is ArcSim's Gauss-Newton one, -ke*shape/2 * dtheta dtheta^T (exact at theta_rest).
// Inputs:
//   x           12-vector (edge x0, x1; opposite vertices x2 of face 0 and x3 of face 1) [m]
//   ke          bending stiffness [N m]
//   rest_length l [m]; rest_area_sum A0 + A1 [m^2]; theta_rest rest dihedral angle [rad]
BendingTerms BendingForce(const Vector12d& x, double ke, double rest_length, double rest_area_sum,
                          double theta_rest);

// ArcSim's wind force on one face, split equally among its three nodes (explicit: no Jacobian):
//   v_rel = wind - (v0 + v1 + v2)/3; v_n = n . v_rel;
//   F = density A |v_n| v_n n + drag A (v_rel - v_n n).
// Inputs:
//   x        9-vector of corner positions [m] (gives the unit normal n)
//   v        9-vector of corner velocities [m/s]
//   wind     air velocity at the face [m/s]
//   area     face area A [m^2] (ArcSim uses the material-space area)
//   density  ArcSim wind density [kg/m^3]; drag  ArcSim tangential drag [kg/(m^2 s)]
// Returns the 9-vector of nodal forces [N] (each node gets F/3).
Vector9d WindForce(const Vector9d& x, const Vector9d& v, const Eigen::Vector3d& wind, double area,
                   double density, double drag);

struct RepulsionTerms {
  double energy = 0;   // [J]
  Vector12d force;     // [N] on (p, a, b, c)
  Matrix12d jacobian;  // [N/m] Gauss-Newton: -stiffness v / h g g^T, g = dd/dx
  bool active = false; // within the thickness and the projection inside the triangle
};

// Vertex-face repulsion, ArcSim's proximity constraint (IneqCon): with q the projection of p onto
// the plane of (a,b,c), barycentrics w (all >= 0 when active), n the unit normal,
// d = side * n.(p - q) (side = +1 or -1: the side p is on) and the violation v = h - d > 0,
//   E = stiffness v^3 / (6 h),  f = stiffness v^2 / (2 h) dd/dx,
// a cubic penalty that starts smoothly at the thickness h (no energy jump when a pair appears).
// ArcSim's stiffness is collision_stiffness times min(node area, face area).
// Inputs:
//   x          12-vector (p, a, b, c) [m]
//   side       +1 or -1
//   thickness  h [m] (> 0)
//   stiffness  [N/m]
RepulsionTerms RepulsionForce(const Vector12d& x, double side, double thickness, double stiffness);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_CLOTH_FORCES_H_
