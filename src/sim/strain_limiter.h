#ifndef CLOTHWIND_SIM_STRAIN_LIMITER_H_
#define CLOTHWIND_SIM_STRAIN_LIMITER_H_

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/SVD>

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

// The principal stretches of face f of `mesh` (the singular values of its deformation gradient
// from the rest shape mesh.U to positions x; largest first), as the limiter measures them.
// Inputs: mesh  F and U; x  #V by 3 positions (double or float); f  a face index.
template <typename Positions>
Eigen::Vector2d FacePrincipalStretches(const Mesh& mesh, const Positions& x, int f) {
  Eigen::Matrix2d Dm;
  Dm.col(0) = (mesh.U.row(mesh.F(f, 1)) - mesh.U.row(mesh.F(f, 0))).transpose();
  Dm.col(1) = (mesh.U.row(mesh.F(f, 2)) - mesh.U.row(mesh.F(f, 0))).transpose();
  Eigen::Matrix<double, 3, 2> Ds;
  Ds.col(0) = (x.row(mesh.F(f, 1)) - x.row(mesh.F(f, 0))).template cast<double>().transpose();
  Ds.col(1) = (x.row(mesh.F(f, 2)) - x.row(mesh.F(f, 0))).template cast<double>().transpose();
  return Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(Ds * Dm.inverse()).singularValues();
}

// How StrainLimiter::Project limits stretches:
//   kSweeps  Gauss-Seidel sweeps of per-face projections (the default; FlagSim's datasets)
//   kGlobal  local/global iterations: every face's projection (local), then the positions that
//            best fit all of them at once, mass-weighted, in one sparse solve (global), so a
//            correction reaches the whole sheet in one iteration instead of creeping a face a sweep
enum class StrainLimitMethod { kSweeps, kGlobal };

// How StrainLimiter::Project sweeps (ArcSim's strain_limits, and when its sweeps stop).
struct StrainLimitSettings {
  double min = 0.0;  // lower limit on principal stretches (0: none)
  double max = std::numeric_limits<double>::infinity();  // upper limit (inf: none)
  // Sweeps stop once, over a whole sweep, no face was found outside [min (1 - tolerance),
  // max (1 + tolerance)]; faces outside the limits by less are still projected. 0: until no
  // face is out by more than round-off (1e-6).
  double tolerance = 0.0;
  int max_sweeps = 4;  // kGlobal: at most this many local/global iterations
  StrainLimitMethod method = StrainLimitMethod::kSweeps;
};

// What one Project call did.
struct StrainLimitResult {
  // Faces found outside the limits in the first sweep (each checked in its turn, after the
  // projections of the faces before it).
  int initially_violated = 0;
  int sweeps = 0;              // sweeps run (<= max_sweeps)
  // Largest relative excess found in the last sweep, before its projections: max over faces of
  // s_max / max - 1 and 1 - s_min / min (0 when none); when converged, <= tolerance (give or take
  // the 1e-6 round-off slack on squared stretches that decides which faces are projected).
  double excess = 0.0;
  bool converged = false;  // the last sweep found no face outside the limits by more than tolerance
};

// Keeps every face's principal stretches (the singular values of its deformation gradient) within
// [min, max], as ArcSim's strain limiting does, but by Gauss-Seidel sweeps of per-face
// projections instead of ArcSim's global constrained optimisation (43 % of its run time): a face
// out of limits gets the shape whose stretches are clamped to the limits, its stretch
// directions, rotation and mass-weighted centroid kept; pinned vertices do not move. The
// same position change, divided by the time step, is added to the velocities (ArcSim updates
// velocities likewise).
class StrainLimiter {
 public:
  // Inputs:
  //   mesh    F and U (rest coordinates) are used
  //   mass    #V node masses [kg]
  //   pinned  #V flags (non-zero: vertex does not move)
  StrainLimiter(const Mesh& mesh, const Eigen::VectorXd& mass, const std::vector<char>& pinned);
  // Not copied: copies would share the global method's scratch space.
  StrainLimiter(const StrainLimiter&) = delete;
  StrainLimiter& operator=(const StrainLimiter&) = delete;

  // Sweeps until converged (see StrainLimitSettings) or settings.max_sweeps. The sweeps converge
  // slowly, for two reasons measured in stop 73 (docs/simulator.md, "Strain limiting"):
  //  - a flag in the wind is stretched along its whole length, and a projection pulls a face's
  //    far vertex in and pushes its pole-side vertex out, so the correction creeps one face per
  //    sweep towards the pole (over-relaxing the projections carried it faster on our flag
  //    scene but made ArcSim's own flag scene go wild, so it is not done);
  //  - a face's projection keeps its mass-weighted centroid but is not the closest shape in
  //    the mass-weighted metric, so around a pinned corner the sweeps can settle into a cycle
  //    that leaves every face of the fan ~0.3 % over the limit however many sweeps run.
  // Inputs:
  //   settings  limits (validated by the caller: StrainLimitsAreValid, max_sweeps >= 1,
  //             tolerance >= 0)
  //   dt        time step [s] (> 0) for the velocity update
  //   x, v      #V by 3 positions [m] and velocities [m/s], updated in place
  // Returns what the sweeps did. Throws std::invalid_argument, naming the vertex and changing
  // nothing, when a position is not finite.
  StrainLimitResult Project(const StrainLimitSettings& settings, double dt, Eigen::MatrixX3d* x,
                            Eigen::MatrixX3d* v);

 private:
  // The kSweeps and kGlobal methods on the interleaved positions work_ (Project's inputs).
  StrainLimitResult Sweep(const StrainLimitSettings& settings);
  StrainLimitResult LocalGlobal(const StrainLimitSettings& settings);
  // Builds and factorises the global step's matrix (once, on the first kGlobal call).
  void PrepareGlobal();

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
  // kGlobal: the global step's #V by #V matrix, factorised (empty until first used), and what
  // builds it.
  struct Global;
  std::shared_ptr<Global> global_;
  Eigen::VectorXd mass_;
  std::vector<char> pinned_;
  std::vector<double> face_weight_;  // kGlobal: each face's weight in the fit (its mass · area)
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_STRAIN_LIMITER_H_
