#ifndef CLOTHWIND_SIM_STRAIN_LIMITER_H_
#define CLOTHWIND_SIM_STRAIN_LIMITER_H_

#include <vector>

#include <Eigen/Core>

#include "sim/mesh.h"

namespace clothwind::sim {

// The principal-stretch limits a scene (ArcSim's strain_limits) and the simulator accept: one
// rule for both (the scene reader once refused [0, 1.05], which the simulator takes as "no lower
// limit", and passed [1, 1], which the simulator refused naming no file).
// Inputs: min, max  the limits (max may be infinite: no upper limit; min 0: no lower one).
// Returns whether 0 <= min <= 1 <= max and min < max.
inline bool StrainLimitsAreValid(double min, double max) {
  return min >= 0 && min <= 1 && max >= 1 && min < max;
}
constexpr const char* kStrainLimitsRule =
    "0 <= min <= 1 <= max and min < max (min 0: no lower limit; max inf: no upper one)";

// Keeps every face's principal stretches (the singular values of its deformation gradient) within
// [strain_min, strain_max], as ArcSim's strain limiting does, but by a few Gauss-Seidel sweeps of
// per-face projections instead of ArcSim's global constrained optimisation (43 % of its run time):
// a face out of limits is replaced by the closest (mass-weighted, rotation kept) shape whose
// stretches are clamped to the limits; pinned vertices do not move. The same position change,
// divided by the time step, is added to the velocities (ArcSim updates velocities likewise).
class StrainLimiter {
 public:
  // Inputs:
  //   mesh    F and U (rest coordinates) are used
  //   mass    #V node masses [kg]
  //   pinned  #V flags (non-zero: vertex does not move)
  StrainLimiter(const Mesh& mesh, const Eigen::VectorXd& mass, const std::vector<char>& pinned);

  // Inputs:
  //   strain_min, strain_max  limits on principal stretches (0 / inf: that side off)
  //   iterations              sweeps (stops early once every face is within limits)
  //   dt                      time step [s] (> 0) for the velocity update
  //   x, v                    #V by 3 positions [m] and velocities [m/s], updated in place
  // Returns the number of faces that were outside the limits before projection.
  int Project(double strain_min, double strain_max, int iterations, double dt, Eigen::MatrixX3d* x,
              Eigen::MatrixX3d* v);

 private:
  struct Face {
    int v[3];
    Eigen::Matrix2d Dm_inv;
    double w[3];            // projection weights (masses, huge for pinned vertices; sum 1)
    bool pinned[3];
    Eigen::Vector2d du[3];  // u_i - weighted centroid of u
  };
  std::vector<Face> faces_;
  std::vector<double> work_;  // interleaved positions during the sweeps
  std::vector<char> moved_, moved_next_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_STRAIN_LIMITER_H_
