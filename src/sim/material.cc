#include "sim/material.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "common/formatted.h"
#include "common/json_file.h"
#include "sim/json_comments.h"
#include "sim/warn_once.h"

namespace clothwind::sim {
namespace {

// ArcSim's stretching sample grid: 30 samples per axis over G00, G11 in [-0.25, 0.7167] and
// |G01| in [0, 0.9667] (dde.cpp).
constexpr int kSamples = 30;


// One stretching sample, as ArcSim's evaluate_stretching_sample: the principal stretch w0 (the
// larger one) and its direction in material space pick a point between the unstretched row and
// the 5 directional rows (stretch 1 + 1/6 at full weight); negative stiffnesses clamp to 0 and
// the result is doubled.
Eigen::Vector4d EvaluateStretchingSample(const Eigen::Matrix2d& G,
                                         const std::array<std::array<Eigen::Vector4d, 5>, 2>& d) {
  const Eigen::Matrix2d C = 2.0 * G + Eigen::Matrix2d::Identity();  // right Cauchy-Green tensor
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(C);
  // Eigen sorts ascending; ArcSim's first eigenpair is the largest.
  const double w0 = std::sqrt(std::max(0.0, eig.eigenvalues()[1]));
  const Eigen::Vector2d dir = eig.eigenvectors().col(1);
  // Direction folded into [0, 90] degrees: the samples hold |G01|, so a direction and its
  // mirror image are the same sample; ArcSim's |atan2| / pi * 8 clamps at 4 for the same range.
  double angle = std::atan2(std::abs(dir.y()), std::abs(dir.x()));  // [0, pi/2]
  double angle_weight = std::clamp(angle / M_PI * 8.0, 0.0, 4.0 - 1e-6);
  const int angle_id = static_cast<int>(angle_weight);
  angle_weight -= angle_id;
  const double strain_weight = std::clamp((w0 - 1.0) * 6.0, 0.0, 1.0 - 1e-6);
  Eigen::Vector4d k = d[0][angle_id] * (1 - strain_weight) * (1 - angle_weight) +
                      d[1][angle_id] * strain_weight * (1 - angle_weight) +
                      d[0][angle_id + 1] * (1 - strain_weight) * angle_weight +
                      d[1][angle_id + 1] * strain_weight * angle_weight;
  return 2.0 * k.cwiseMax(0.0);
}

void CheckPositive(double value, const char* what) {
  if (!(std::isfinite(value) && value > 0))
    throw std::invalid_argument(std::string("material: ") + what + " must be finite and > 0, got " +
                                std::to_string(value));
}

}  // namespace

Eigen::Vector4d Material::StretchingStiffness(const Eigen::Matrix2d& G) const {
  double a = std::clamp((G(0, 0) + 0.25) * kSamples, 0.0, kSamples - 1 - 1e-5);
  double b = std::clamp((G(1, 1) + 0.25) * kSamples, 0.0, kSamples - 1 - 1e-5);
  double c = std::clamp(std::abs(G(0, 1)) * kSamples, 0.0, kSamples - 1 - 1e-5);
  const int ai = std::min(static_cast<int>(a), kSamples - 2);
  const int bi = std::min(static_cast<int>(b), kSamples - 2);
  const int ci = std::min(static_cast<int>(c), kSamples - 2);
  a -= ai;
  b -= bi;
  c -= ci;
  Eigen::Vector4d k = Eigen::Vector4d::Zero();
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int l = 0; l < 2; ++l) {
        const double w = (i ? a : 1 - a) * (j ? b : 1 - b) * (l ? c : 1 - c);
        k += w * stretching_samples[((ai + i) * kSamples + (bi + j)) * kSamples + (ci + l)];
      }
  return k;
}

std::array<double, 5> Material::BendingRow(const Eigen::Vector2d& du) const {
  // Edge direction in material space folded to [0, 2] (0, 45, 90 degrees), ArcSim's bias_angle.
  double bias = std::atan2(du.y(), du.x()) * 4.0 / M_PI;
  if (bias < 0) bias = -bias;
  if (bias > 4) bias = 8 - bias;
  if (bias > 2) bias = 4 - bias;
  const int bias_id = std::clamp(static_cast<int>(bias), 0, 1);
  bias -= bias_id;
  std::array<double, 5> row;
  for (int j = 0; j < 5; ++j) row[j] = bending[bias_id][j] * (1 - bias) + bending[bias_id + 1][j] * bias;
  return row;
}

double Material::BendingStiffnessFromRow(double curvature, const std::array<double, 5>& row) {
  // Curvature samples every 10 1/m (ArcSim: value = curv/2 * 0.2, clamped to [0, 4]). ArcSim
  // passes a signed curvature and so extrapolates below the first sample for negative dihedrals,
  // which depends on the arbitrary edge orientation; the measured tables are for a magnitude.
  // A NaN curvature (a state already broken) gives a NaN stiffness, which the step's force check
  // reports; cast to an index it was undefined behaviour (a scene with a repulsion thickness of
  // 1e200 crashed here).
  if (std::isnan(curvature)) return curvature;
  double value = std::min(std::abs(curvature) * 0.1, 4.0);
  const int value_i = std::clamp(static_cast<int>(value), 0, 3);
  value -= value_i;
  return std::max(row[value_i] * (1 - value) + row[value_i + 1] * value, 0.0);
}

double Material::BendingStiffness(double curvature, const Eigen::Vector2d& du) const {
  // Bilinear in (direction, curvature), evaluated direction first (the simulator caches the row).
  return BendingStiffnessFromRow(curvature, BendingRow(du));
}

Material MakeMaterial(double density, const Eigen::Matrix<double, 6, 4>& stretching,
                      const Eigen::Matrix<double, 3, 5>& bending, const MaterialMultipliers& mult) {
  CheckPositive(density, "density");
  CheckPositive(mult.density, "density multiplier");
  CheckPositive(mult.stretching, "stretching multiplier");
  CheckPositive(mult.bending, "bending multiplier");
  CheckPositive(mult.thicken, "thicken");
  if (!(std::isfinite(mult.damping) && mult.damping >= 0))
    throw std::invalid_argument("material: damping must be finite and >= 0");
  if (!stretching.allFinite()) throw std::invalid_argument("material: stretching table has non-finite values");
  if (!bending.allFinite()) throw std::invalid_argument("material: bending table has non-finite values");
  Material m;
  m.density = density * mult.density * mult.thicken;
  if (!(m.density <= kMaxAreaWeight))
    throw std::invalid_argument("material: area weight after multipliers (density " + Formatted("%g", density) + " x density_mult " +
                                Formatted("%g", mult.density) + " x thicken " + Formatted("%g", mult.thicken) + ") = " + Formatted("%g", m.density) +
                                " kg/m^2 must be at most " + Formatted("%g", kMaxAreaWeight) + " kg/m^2");
  m.stretching_scale = mult.stretching * mult.thicken;
  m.damping = mult.damping;
  // ArcSim's layout: d[0][*] = row 0 for every direction, d[1][i] = row i + 1.
  for (int i = 0; i < 5; ++i) {
    m.stretching_data[0][i] = stretching.row(0).transpose();
    m.stretching_data[1][i] = stretching.row(i + 1).transpose();
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 5; ++j) m.bending[i][j] = bending(i, j) * mult.bending * mult.thicken;
  // Finite tables times finite multipliers can still overflow (1e300 x 2), which surfaced only as
  // a non-finite force at the first step, naming no field.
  if (!std::isfinite(2 * m.stretching_scale * stretching.cwiseAbs().maxCoeff()))  // (samples: 2 k)
    throw std::invalid_argument("material: stretching table x stretching_mult x thicken overflows");
  if (!std::isfinite(bending.cwiseAbs().maxCoeff() * mult.bending * mult.thicken))
    throw std::invalid_argument("material: bending table x bending_mult x thicken overflows");
  m.stretching_samples.resize(kSamples * kSamples * kSamples);
  for (int i = 0; i < kSamples; ++i)
    for (int j = 0; j < kSamples; ++j)
      for (int k = 0; k < kSamples; ++k) {
        Eigen::Matrix2d G;
        G(0, 0) = -0.25 + i / double(kSamples);
        G(1, 1) = -0.25 + j / double(kSamples);
        G(0, 1) = G(1, 0) = k / double(kSamples);
        m.stretching_samples[(i * kSamples + j) * kSamples + k] =
            m.stretching_scale * EvaluateStretchingSample(G, m.stretching_data);
      }
  return m;
}

namespace {

// The material file's JSON object (ArcSim's comments allowed). Throws std::runtime_error naming
// the file when it cannot be read, parsed, or is not an object.
nlohmann::json ReadMaterialJson(const std::string& path) {
  const std::string text = ReadTextFile(path, "a material file");
  nlohmann::json j;
  try {
    j = ParseJsonWithComments(text);
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": not valid JSON: " + JsonErrorText(e));
  } catch (const std::runtime_error& e) {  // an unclosed block comment
    throw std::runtime_error(path + ": " + e.what());
  }
  if (!j.is_object()) throw std::runtime_error(path + ": expected a JSON object at the top level");
  return j;
}

std::vector<std::string> IgnoredKeyWarnings(const nlohmann::json& j, const std::string& path) {
  static const std::set<std::string> kRead = {"density", "stretching", "bending"};
  // Fields of a scene's material entry, which ArcSim does not read from a material file either:
  // damping and strain_limits are simulated from the scene's entry, yield_curv and weakening
  // (plasticity) are not simulated at all.
  static const std::set<std::string> kSceneEntry = {"damping", "strain_limits"};
  static const std::set<std::string> kNotSimulated = {"yield_curv", "weakening"};
  std::vector<std::string> warnings;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (kRead.count(it.key())) continue;
    warnings.push_back(path + ": key '" + it.key() + "' " +
                       (kSceneEntry.count(it.key())
                            ? "belongs in the scene's materials[] entry (ArcSim ignores it in a material file "
                              "too), ignored here"
                        : kNotSimulated.count(it.key())
                            ? "belongs in the scene's materials[] entry, and plasticity is not simulated here, ignored"
                            : "is not a material field (density, stretching, bending), ignored"));
  }
  return warnings;
}

}  // namespace

std::vector<std::string> ArcSimMaterialWarnings(const std::string& path) {
  return IgnoredKeyWarnings(ReadMaterialJson(path), path);
}

Material LoadArcSimMaterial(const std::string& path, const MaterialMultipliers& mult) {
  const nlohmann::json j = ReadMaterialJson(path);
  WarnOnce(IgnoredKeyWarnings(j, path));
  auto number = [&](const nlohmann::json& v, const std::string& field) {
    if (!v.is_number())
      throw std::runtime_error(path + ": field '" + field + "' must be a number, got " + v.dump());
    const double x = v.get<double>();
    if (!std::isfinite(x)) throw std::runtime_error(path + ": field '" + field + "' is not finite");
    return x;
  };
  auto table = [&](const char* field, int rows, int cols) {
    if (!j.contains(field)) throw std::runtime_error(path + ": missing field '" + field + "'");
    const auto& t = j[field];
    if (!t.is_array() || static_cast<int>(t.size()) != rows)
      throw std::runtime_error(path + ": field '" + field + "' must be an array of " +
                               std::to_string(rows) + " rows of " + std::to_string(cols) + " numbers");
    Eigen::MatrixXd out(rows, cols);
    for (int r = 0; r < rows; ++r) {
      if (!t[r].is_array() || static_cast<int>(t[r].size()) != cols)
        throw std::runtime_error(path + ": field '" + field + "' row " + std::to_string(r) +
                                 " must have " + std::to_string(cols) + " numbers");
      for (int c = 0; c < cols; ++c)
        out(r, c) = number(t[r][c], std::string(field) + "[" + std::to_string(r) + "][" +
                                        std::to_string(c) + "]");
    }
    return out;
  };
  if (!j.contains("density")) throw std::runtime_error(path + ": missing field 'density'");
  const double density = number(j["density"], "density");
  if (!(density > 0)) throw std::runtime_error(path + ": field 'density' must be > 0 [kg/m^2]");
  if (!(density <= kMaxAreaWeight))
    throw std::runtime_error(path + ": field 'density' is " + Formatted("%g", density) + " kg/m^2, expected at most " +
                             Formatted("%g", kMaxAreaWeight) + " kg/m^2 (fabrics: 0.05-1)");
  const Eigen::Matrix<double, 6, 4> stretching = table("stretching", 6, 4);
  // Columns 0, 2 and 3 are the warp, weft and shear stiffnesses (1, their coupling, may be 0, as
  // in paper.json): each needs a value > 0 somewhere, or the cloth has none in that direction
  // after the clamping to >= 0 (an all-zero or all-negative table ran silently as a cloth that
  // does not resist stretching).
  for (const int c : {0, 2, 3}) {
    if (!(stretching.col(c).maxCoeff() > 0))
      throw std::runtime_error(path + ": field 'stretching' column " + std::to_string(c) + " (" +
                               (c == 0 ? "warp" : c == 2 ? "weft" : "shear") + ") has no stiffness > 0");
  }
  const Eigen::Matrix<double, 3, 5> bending = table("bending", 3, 5);
  // Every bending stiffness enters θ, which requires > 0: a zero here failed later naming no file.
  if (!(bending.array() > 0).all())
    throw std::runtime_error(path + ": field 'bending' must hold stiffnesses > 0 [N m]");
  // Each entry at most its bound, named by row and column (see kMaxStretchingEntry).
  auto bounded = [&](const Eigen::MatrixXd& t, const char* field, double max, const char* unit) {
    for (int r = 0; r < t.rows(); ++r)
      for (int c = 0; c < t.cols(); ++c)
        if (!(std::abs(t(r, c)) <= max))
          throw std::runtime_error(path + ": field '" + field + "[" + std::to_string(r) + "][" + std::to_string(c) +
                                   "]' is " + Formatted("%g", t(r, c)) + ", expected at most " + Formatted("%g", max) +
                                   unit + " in magnitude");
  };
  bounded(stretching, "stretching", kMaxStretchingEntry, "");
  bounded(bending, "bending", kMaxBendingEntry, " N m");
  try {
    return MakeMaterial(density, stretching, bending, mult);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace clothwind::sim
