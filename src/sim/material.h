#ifndef CLOTHWIND_SIM_MATERIAL_H_
#define CLOTHWIND_SIM_MATERIAL_H_

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace clothwind::sim {

// Scales applied to a material as ArcSim's scene files do (`density_mult`, `stretching_mult`,
// `bending_mult`, `thicken`; thicken multiplies all three) plus ArcSim's `damping`.
// Area weights above this are no cloth (1000 kg/m^2: a 13 cm steel plate; fabrics weigh 0.05-1,
// ArcSim's heaviest material 0.324), and far above it the step's numbers overflow.
constexpr double kMaxAreaWeight = 1e3;  // [kg/m^2]
// Bounds on a material file's table entries, far past any measured material (ArcSim's fabrics:
// stretching up to ~2e3, its aluminium 1.8e6; bending up to 4e-4 N m for its paper): a typo
// such as 1e30 is refused naming the entry, where it blew the simulation up naming nothing.
constexpr double kMaxStretchingEntry = 1e9;
constexpr double kMaxBendingEntry = 1e3;  // [N m]

struct MaterialMultipliers {
  double density = 1.0;
  double stretching = 1.0;
  double bending = 1.0;
  double thicken = 1.0;
  double damping = 0.0;  // stiffness-proportional (Rayleigh) damping coefficient [s]
};

// A Wang et al. 2011 data-driven cloth material, interpreted as ArcSim 0.2 does (docs/simulator.md).
//
// Stretching: the JSON's 6 rows of 4 stiffnesses (k11, k12, k22, k33) [N/m] are arranged as
// ArcSim's StretchingData d[2][5]: row 0 is the unstretched sample for all 5 directions, rows 1..5
// are the directions 0, 22.5, 45, 67.5, 90 degrees at a principal stretch of 1 + 1/6. The stiffness
// for a Green strain G is interpolated from a 30^3 grid over (G00, G11, |G01|) precomputed from
// those samples (ArcSim's evaluate_stretching_samples), already doubled as ArcSim does, and scaled
// by the stretching multiplier. Energy density (per rest area):
//   W = 1/2 (k0 G00^2 + 2 k1 G00 G11 + k2 G11^2 + 2 k3 G01^2).
// Bending: 3 directions (0, 45, 90 degrees of the hinge edge in material space) by 5 curvatures
// (0, 10, 20, 30, 40 1/m of ArcSim's curvature theta*l/(A0+A1)), bilinearly interpolated.
struct Material {
  double density = 0;                               // area density after multipliers [kg/m^2]
  std::array<std::array<Eigen::Vector4d, 5>, 2> stretching_data{};  // ArcSim d[2][5], as read [N/m]
  std::array<std::array<double, 5>, 3> bending{};   // after multipliers [N m]
  double stretching_scale = 1;                      // stretching multiplier applied to samples
  double damping = 0;                               // Rayleigh stiffness damping [s]
  std::vector<Eigen::Vector4d> stretching_samples;  // 30^3 grid, index (i*30 + j)*30 + k

  // Stretching stiffness (k11, k12, k22, k33) [N/m] at Green strain G (2 by 2 symmetric,
  // material axes), trilinearly interpolated on the sample grid exactly as ArcSim's
  // stretching_stiffness (clamped outside the grid).
  Eigen::Vector4d StretchingStiffness(const Eigen::Matrix2d& G) const;

  // Bending stiffness [N m] for a hinge whose edge has material-space direction du (2-vector,
  // any length > 0) and ArcSim curvature `curvature` = |theta| l / (A0 + A1) [1/m].
  double BendingStiffness(double curvature, const Eigen::Vector2d& du) const;

  // The bending table interpolated for hinge direction du (5 curvature samples) [N m]; with
  // BendingStiffnessFromRow this is BendingStiffness split in two, so the simulator computes the
  // direction part once per hinge.
  std::array<double, 5> BendingRow(const Eigen::Vector2d& du) const;
  static double BendingStiffnessFromRow(double curvature, const std::array<double, 5>& row);
};

// Builds a material from the raw tables (as in ArcSim's JSON files) and multipliers.
// Inputs:
//   density     area density [kg/m^2], > 0
//   stretching  6 by 4 table [N/m] (row 0: unstretched; rows 1..5: 5 directions)
//   bending     3 by 5 table [N m]
//   mult        multipliers (thicken multiplies density, stretching and bending)
// Throws std::invalid_argument on non-finite or non-positive values / multipliers, an area weight
// after multipliers above 1000 kg/m^2, or tables whose product with the multipliers overflows.
Material MakeMaterial(double density, const Eigen::Matrix<double, 6, 4>& stretching,
                      const Eigen::Matrix<double, 3, 5>& bending,
                      const MaterialMultipliers& mult = {});

// Loads an ArcSim material JSON ({"density": d, "stretching": 6x4, "bending": 3x5}; comments
// `// ...` at the top are allowed, as in ArcSim's files) and applies the multipliers.
// Inputs:
//   path  the JSON file
//   mult  multipliers as in an ArcSim scene's material entry
// Keys other than density, stretching and bending are ignored with a warning (damping and
// strain_limits belong in the scene's material entry, where they are simulated; yield_curv and
// weakening too, not simulated; anything else is likely misspelt),
// printed to stderr once per file and key in a process: a dataset run loads one material for
// every simulation.
// Throws std::runtime_error naming the file and the missing/bad field and what was expected.
Material LoadArcSimMaterial(const std::string& path, const MaterialMultipliers& mult = {});

// The warnings LoadArcSimMaterial gives for the material file `path` (for tests and callers that
// report them their own way): one line per ignored key, "<path>: key 'k' ...". Throws as
// LoadArcSimMaterial when the file cannot be read or parsed.
std::vector<std::string> ArcSimMaterialWarnings(const std::string& path);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_MATERIAL_H_
