#include "sim/scene.h"

#include <cstdint>
#include <cstdio>
#include <limits>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <regex>
#include <set>
#include <stdexcept>

#include "common/formatted.h"
#include "common/json_file.h"
#include "sim/json_comments.h"
#include "sim/strain_limiter.h"
#include "sim/turbulent_wind.h"

namespace clothwind::sim {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Physically sane ranges. A value far outside them is a typo or a hostile file, and the numbers
// downstream overflow: with gravity 1e200 the solve's residual norm was inf / inf = NaN, which
// ended the solve at once, and the scene ran to its end (exit 0) with a cloth that never moved.
// Every scene in config/ and ArcSim's own are far inside (gravity 9.8, wind <= 10 m/s, thicken 2,
// multipliers 1).
constexpr double kMaxAcceleration = 1000;  // |gravity| [m/s^2]: 100 g
constexpr double kMaxWindSpeed = 1000;     // |wind velocity|, gust amplitude [m/s]: 3x the speed of sound
// A cloth's initial velocity: the simulator's default max_speed (a faster node ends the first
// step as exploded); the spin 1000 rad/s (~160 turns a second), the origin's distance 1e4 m (the
// builder keeps the cloth itself within 100 m, and refuses initial node speeds past max_speed).
constexpr double kMaxClothSpeed = 1000;    // [m/s]
constexpr double kMaxClothSpin = 1000;     // [rad/s]
constexpr double kMaxVelocityOrigin = 1e4; // [m]
constexpr double kMaxMultiplier = 1e6;     // thicken and the density/stretching/bending multipliers
constexpr double kMaxDamping = 1000;       // stiffness-proportional damping [s] (cloth: ~0.01 s)
constexpr double kMaxAirDensity = 1e4;     // wind density [kg/m^3] (water: 1000)
constexpr double kMaxAirDrag = 1e6;        // wind drag [kg/(m^2 s)]
constexpr double kMaxTurbulence = kMaxTurbulenceIntensity;  // intensity and component ratios (~0.1-0.3 outdoors)

const char* TypeName(const json& j) { return j.type_name(); }

// A value as the message shows it: a number or short text as written (-1, 8.5, "3"), anything
// else by its type ("got array"), so an error says what was found.
std::string Shown(const json& j) {
  if (j.is_number() || j.is_boolean() || (j.is_string() && j.get<std::string>().size() <= 40)) return j.dump();
  return j.type_name();
}

// Walks the JSON with the file name and the JSON path at hand, so every message names both.
class Reader {
 public:
  Reader(std::string file, WarningSink warn) : file_(std::move(file)), warn_(std::move(warn)) {}

  [[noreturn]] void Fail(const std::string& path, const std::string& what) const {
    throw std::runtime_error(file_ + ": " + path + ": " + what);
  }
  void Warn(const std::string& path, const std::string& what) const {
    warn_(file_ + ": " + path + ": " + what);
  }

  void ExpectObject(const json& j, const std::string& path) const {
    if (!j.is_object()) Fail(path, std::string("expected an object, got ") + TypeName(j));
  }
  void ExpectArray(const json& j, const std::string& path) const {
    if (!j.is_array()) Fail(path, std::string("expected an array, got ") + TypeName(j));
  }
  // Warns about keys that are neither understood nor deliberately ignored.
  void CheckKeys(const json& obj, const std::string& path, const std::set<std::string>& known,
                 const std::set<std::string>& ignored = {}) const {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      const std::string child = path.empty() ? it.key() : path + "." + it.key();
      if (known.count(it.key())) continue;
      if (ignored.count(it.key())) {
        Warn(child, "ArcSim key not supported by this simulator, ignored");
      } else {
        Warn(child, "unknown key, ignored");
      }
    }
  }

  double Number(const json& j, const std::string& path) const {
    if (!j.is_number()) Fail(path, std::string("expected a number, got ") + TypeName(j));
    const double v = j.get<double>();
    if (!std::isfinite(v)) Fail(path, "expected a finite number");
    return v;
  }
  double Positive(const json& j, const std::string& path) const {
    const double v = Number(j, path);
    if (!(v > 0)) Fail(path, "expected a number > 0, got " + std::to_string(v));
    return v;
  }
  double NonNegative(const json& j, const std::string& path) const {
    const double v = Number(j, path);
    if (v < 0) Fail(path, "expected a number >= 0, got " + std::to_string(v));
    return v;
  }
  int Integer(const json& j, const std::string& path) const {
    // A whole number written with a point (8.0) is the integer, as ArcSim's JSON reader takes it.
    if (j.is_number_float() && std::isfinite(j.get<double>()) && j.get<double>() == std::floor(j.get<double>()) &&
        std::abs(j.get<double>()) <= std::numeric_limits<int>::max())
      return static_cast<int>(j.get<double>());
    if (!j.is_number_integer()) Fail(path, "expected an integer, got " + Shown(j));
    // get<int> wraps 4294967297 to 1: out of int's range is an error, not another number.
    const bool in_range = j.is_number_unsigned()
                              ? j.get<uint64_t>() <= static_cast<uint64_t>(std::numeric_limits<int>::max())
                              : j.get<int64_t>() >= std::numeric_limits<int>::min() &&
                                    j.get<int64_t>() <= std::numeric_limits<int>::max();
    if (!in_range) Fail(path, "expected an integer within int's range, got " + j.dump());
    return j.get<int>();
  }
  std::string String(const json& j, const std::string& path) const {
    if (!j.is_string()) Fail(path, std::string("expected a string, got ") + TypeName(j));
    return j.get<std::string>();
  }
  std::vector<double> Numbers(const json& j, const std::string& path, size_t min_n,
                              size_t max_n) const {
    ExpectArray(j, path);
    if (j.size() < min_n || j.size() > max_n) {
      Fail(path, "expected " +
                     (min_n == max_n ? std::to_string(min_n)
                                     : std::to_string(min_n) + " to " + std::to_string(max_n)) +
                     " numbers, got " + std::to_string(j.size()));
    }
    std::vector<double> v;
    for (size_t i = 0; i < j.size(); ++i) v.push_back(Number(j[i], Index(path, i)));
    return v;
  }
  Eigen::Vector3d Vector3(const json& j, const std::string& path) const {
    const auto v = Numbers(j, path, 3, 3);
    return {v[0], v[1], v[2]};
  }
  // A 3-vector whose length is at most max_norm (`unit` names it in the message).
  Eigen::Vector3d BoundedVector3(const json& j, const std::string& path, double max_norm, const char* unit) const {
    const Eigen::Vector3d v = Vector3(j, path);
    const double length = v.stableNorm();  // (norm() overflows to inf from ~1e154 on)
    if (!(length <= max_norm))
      Fail(path, "expected a length of at most " + Formatted("%g", max_norm) + " " + unit + ", got " + Formatted("%g", length));
    return v;
  }
  // A number in (0, max].
  double PositiveAtMost(const json& j, const std::string& path, double max, const char* unit = "") const {
    const double v = Positive(j, path);
    if (!(v <= max)) Fail(path, "expected a number in (0, " + Formatted("%g", max) + "]" + unit + ", got " + Formatted("%g", v));
    return v;
  }
  // A number in [0, max].
  double NonNegativeAtMost(const json& j, const std::string& path, double max, const char* unit = "") const {
    const double v = NonNegative(j, path);
    if (!(v <= max)) Fail(path, "expected a number in [0, " + Formatted("%g", max) + "]" + unit + ", got " + Formatted("%g", v));
    return v;
  }
  // A file named in the scene, resolved (ResolveScenePath) and required to exist.
  std::string File(const json& j, const std::string& path) const {
    const std::string rel = String(j, path);
    const std::string found = ResolveScenePath(file_, rel);
    if (found.empty()) {
      const fs::path dir = fs::path(file_).parent_path();
      std::error_code ec;
      if (fs::path(rel).is_absolute())
        Fail(path, "file '" + rel + "' " + (fs::is_directory(rel, ec) ? "is a folder; expected a file" : "not found"));
      for (const fs::path& base : {dir, dir.parent_path(), fs::current_path(ec)})
        if (fs::is_directory(base / rel, ec))
          Fail(path, "'" + rel + "' is a folder (" + (base / rel).lexically_normal().string() + "); expected a file");
      Fail(path, "file '" + rel + "' not found (looked next to the scene in " + dir.string() +
                     ", in " + dir.parent_path().string() + " and in the working directory)");
    }
    return found;
  }

  static std::string Index(const std::string& path, size_t i) {
    return path + "[" + std::to_string(i) + "]";
  }

 private:
  std::string file_;
  WarningSink warn_;
};

SceneTransform ParseTransform(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"translate", "rotate", "scale"});
  SceneTransform t;
  if (j.contains("translate")) t.translate = r.Vector3(j["translate"], path + ".translate");
  if (j.contains("rotate")) {
    const auto v = r.Numbers(j["rotate"], path + ".rotate", 4, 4);
    t.rotate_deg = v[0];
    t.rotate_axis = Eigen::Vector3d(v[1], v[2], v[3]);
    if (t.rotate_deg != 0.0 && t.rotate_axis.norm() == 0.0) {
      r.Fail(path + ".rotate", "rotation axis [1..3] must not be zero");
    }
  }
  // Within [1e-4, 1e4] (a mesh modelled in mm takes 1e-3): 1e-300 made every face "degenerate",
  // blamed on the OBJ.
  if (j.contains("scale")) {
    t.scale = r.Positive(j["scale"], path + ".scale");
    if (!(t.scale >= 1e-4 && t.scale <= 1e4))
      r.Fail(path + ".scale", "expected a scale in [1e-4, 1e4], got " + Formatted("%g", t.scale));
  }
  return t;
}

SceneMaterial ParseMaterial(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path,
              {"data", "thicken", "density_mult", "stretching_mult", "bending_mult", "damping",
               "strain_limits"},
              {"yield_curv", "weakening", "plastic_flow", "plastic_limit"});
  SceneMaterial m;
  if (!j.contains("data")) r.Fail(path + ".data", "missing (the material JSON file)");
  m.data = r.File(j["data"], path + ".data");
  if (j.contains("thicken")) m.thicken = r.PositiveAtMost(j["thicken"], path + ".thicken", kMaxMultiplier);
  if (j.contains("density_mult")) {
    m.density_mult = r.PositiveAtMost(j["density_mult"], path + ".density_mult", kMaxMultiplier);
  }
  if (j.contains("stretching_mult")) {
    m.stretching_mult = r.PositiveAtMost(j["stretching_mult"], path + ".stretching_mult", kMaxMultiplier);
  }
  if (j.contains("bending_mult")) {
    m.bending_mult = r.PositiveAtMost(j["bending_mult"], path + ".bending_mult", kMaxMultiplier);
  }
  if (j.contains("damping")) m.damping = r.NonNegativeAtMost(j["damping"], path + ".damping", kMaxDamping, " s");
  if (j.contains("strain_limits")) {
    const auto v = r.Numbers(j["strain_limits"], path + ".strain_limits", 2, 2);
    if (!StrainLimitsAreValid(v[0], v[1])) {
      r.Fail(path + ".strain_limits", std::string("expected [min, max] with ") + kStrainLimitsRule);
    }
    m.strain_min = v[0];
    m.strain_max = v[1];
    m.has_strain_limits = true;
  }
  return m;
}

SceneRemeshing ParseRemeshing(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"refine_angle", "refine_compression", "refine_velocity", "size", "aspect_min"});
  SceneRemeshing m;
  m.present = true;
  if (j.contains("refine_angle")) m.refine_angle = r.NonNegative(j["refine_angle"], path + ".refine_angle");
  if (j.contains("refine_compression")) {
    m.refine_compression = r.NonNegative(j["refine_compression"], path + ".refine_compression");
  }
  if (j.contains("refine_velocity")) {
    m.refine_velocity = r.NonNegative(j["refine_velocity"], path + ".refine_velocity");
  }
  if (j.contains("aspect_min")) m.aspect_min = r.NonNegative(j["aspect_min"], path + ".aspect_min");
  if (!j.contains("size")) {
    r.Warn(path + ".size", "missing: without a size range this simulator uses the mesh as it is (no remeshing)");
    m.present = false;
    return m;
  }
  const auto v = r.Numbers(j["size"], path + ".size", 2, 2);
  if (!(v[0] > 0 && v[1] >= v[0])) r.Fail(path + ".size", "expected [min, max] with 0 < min <= max [m]");
  m.size_min = v[0];
  m.size_max = v[1];
  return m;
}

// ArcSim's object form ({"linear", "angular", "origin"}); a bare [vx, vy, vz], as the wind's, is
// refused rather than guessed at.
SceneVelocity ParseVelocity(const Reader& r, const json& j, const std::string& path) {
  if (j.is_array())
    r.Fail(path, "expected an object {\"linear\": [m/s], \"angular\": [rad/s], \"origin\": [m]} (ArcSim's form), "
                 "got an array: write [vx, vy, vz] as {\"linear\": [vx, vy, vz]}");
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"linear", "angular", "origin"});
  SceneVelocity v;
  if (j.contains("linear")) v.linear = r.BoundedVector3(j["linear"], path + ".linear", kMaxClothSpeed, "m/s");
  if (j.contains("angular"))
    v.angular = r.BoundedVector3(j["angular"], path + ".angular", kMaxClothSpin, "rad/s");
  if (j.contains("origin")) v.origin = r.BoundedVector3(j["origin"], path + ".origin", kMaxVelocityOrigin, "m");
  return v;
}

SceneCloth ParseCloth(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"mesh", "transform", "velocity", "materials", "remeshing"});
  SceneCloth c;
  if (!j.contains("mesh")) r.Fail(path + ".mesh", "missing (the cloth's OBJ file)");
  c.mesh = r.File(j["mesh"], path + ".mesh");
  if (j.contains("transform")) c.transform = ParseTransform(r, j["transform"], path + ".transform");
  if (j.contains("velocity")) c.velocity = ParseVelocity(r, j["velocity"], path + ".velocity");
  if (!j.contains("materials")) r.Fail(path + ".materials", "missing (at least one material)");
  r.ExpectArray(j["materials"], path + ".materials");
  if (j["materials"].empty()) r.Fail(path + ".materials", "expected at least one material");
  for (size_t i = 0; i < j["materials"].size(); ++i) {
    c.materials.push_back(ParseMaterial(r, j["materials"][i], Reader::Index(path + ".materials", i)));
  }
  if (c.materials.size() > 1) {
    r.Warn(path + ".materials", "only the first material is simulated (one material per cloth)");
  }
  if (j.contains("remeshing")) c.remeshing = ParseRemeshing(r, j["remeshing"], path + ".remeshing");
  return c;
}

SceneHandle ParseHandle(const Reader& r, const json& j, const std::string& path, int n_motions) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"nodes", "cloth", "motion", "start_time", "end_time", "type"},
              {"label", "center", "radius", "obstacle", "pivot", "fade_time", "circumference", "u", "axis0", "axis1"});
  SceneHandle h;
  if (j.contains("type")) {
    const std::string type = r.String(j["type"], path + ".type");
    if (type != "node") r.Fail(path + ".type", "only node handles are supported, got '" + type + "'");
  }
  if (!j.contains("nodes") && j.contains("label"))
    r.Fail(path + ".label", "label handles (the nodes an OBJ file labels) are not supported: list the node indices "
                            "to pin in nodes");
  if (!j.contains("nodes")) r.Fail(path + ".nodes", "missing (node indices to pin)");
  r.ExpectArray(j["nodes"], path + ".nodes");
  for (size_t i = 0; i < j["nodes"].size(); ++i) {
    const std::string p = Reader::Index(path + ".nodes", i);
    const int n = r.Integer(j["nodes"][i], p);
    if (n < 0) r.Fail(p, "node index must be >= 0, got " + std::to_string(n));
    h.nodes.push_back(n);
  }
  if (j.contains("cloth")) h.cloth = r.Integer(j["cloth"], path + ".cloth");
  if (j.contains("motion")) {
    h.motion = r.Integer(j["motion"], path + ".motion");
    if (h.motion < 0 || h.motion >= n_motions) {
      r.Fail(path + ".motion", "motion index " + std::to_string(h.motion) + " out of range (" +
                                   std::to_string(n_motions) + " motions)");
    }
    r.Warn(path + ".motion", "moving handles are not simulated; the handle stays fixed");
  }
  if (j.contains("start_time")) h.start_time = r.NonNegative(j["start_time"], path + ".start_time");
  if (j.contains("end_time")) h.end_time = r.NonNegative(j["end_time"], path + ".end_time");
  if (j.contains("start_time") || j.contains("end_time")) {
    r.Warn(path, "handle start_time/end_time are not simulated; the handle holds throughout");
  }
  return h;
}

ShearProfile ParseShear(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"profile", "exponent", "roughness", "reference_height", "ground_z"});
  ShearProfile s;
  const std::string kind = j.contains("profile") ? r.String(j["profile"], path + ".profile") : "power";
  if (kind == "power") {
    s.kind = ShearProfile::Kind::kPower;
  } else if (kind == "log") {
    s.kind = ShearProfile::Kind::kLog;
  } else if (kind == "none") {
    s.kind = ShearProfile::Kind::kNone;
  } else {
    r.Fail(path + ".profile", "expected \"power\", \"log\" or \"none\", got \"" + kind + "\"");
  }
  if (j.contains("exponent")) s.exponent = r.NonNegative(j["exponent"], path + ".exponent");
  if (j.contains("roughness")) s.roughness = r.Positive(j["roughness"], path + ".roughness");
  if (j.contains("reference_height")) {
    s.reference_height = r.Positive(j["reference_height"], path + ".reference_height");
  }
  // Required with a profile: the scene's z is not height above the ground. The flag scene's hoist
  // runs z 0..2 and FlagSim mounts it 4.6 m up, so its ground is at z -4.6; the old default 0 put
  // the ground at the hoist's foot, and `"shear": {}` left the flag hanging in almost no wind.
  if (j.contains("ground_z")) {
    s.ground_z = r.Number(j["ground_z"], path + ".ground_z");
  } else if (s.kind != ShearProfile::Kind::kNone) {
    r.Fail(path + ".ground_z", "expected the ground's z in the scene's frame [m] (required with a profile: z is "
                               "not height above the ground; a flag hoisted 4.6 m up at z 0 has its ground at -4.6)");
  }
  if (s.kind == ShearProfile::Kind::kLog && s.reference_height <= s.roughness) {
    r.Fail(path + ".reference_height", "must exceed the roughness length");
  }
  return s;
}

uint64_t Seed(const Reader& r, const json& j, const std::string& path) {
  if (!j.is_number_unsigned() && !(j.is_number_integer() && j.get<int64_t>() >= 0)) {
    r.Fail(path, "expected an integer >= 0, got " + Shown(j));
  }
  return j.get<uint64_t>();
}

TurbulenceParams ParseTurbulence(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"intensity", "length_scale", "component_ratios", "modes", "seed"});
  TurbulenceParams t;
  if (j.contains("intensity")) {
    t.intensity = r.NonNegativeAtMost(j["intensity"], path + ".intensity", kMaxTurbulence, " (sigma / mean speed)");
  }
  if (j.contains("length_scale")) {
    t.length_scale = r.Number(j["length_scale"], path + ".length_scale");
    if (!(t.length_scale >= kMinTurbulenceLengthScale && t.length_scale <= kMaxTurbulenceLengthScale))
      r.Fail(path + ".length_scale", "expected a length in 0.01..10000 m, got " + std::to_string(t.length_scale));
  }
  if (j.contains("component_ratios")) {
    const auto v = r.Numbers(j["component_ratios"], path + ".component_ratios", 3, 3);
    for (int i = 0; i < 3; ++i) {
      if (!(v[i] >= 0 && v[i] <= kMaxTurbulence))
        r.Fail(path + ".component_ratios", "ratios must be in [0, " + Formatted("%g", kMaxTurbulence) + "]");
      t.component_ratios[i] = v[i];
    }
  }
  if (j.contains("modes")) {
    t.modes = r.Integer(j["modes"], path + ".modes");
    if (t.modes < 1 || t.modes > 10000) r.Fail(path + ".modes", "expected 1..10000 modes");
  }
  if (j.contains("seed")) t.seed = Seed(r, j["seed"], path + ".seed");
  return t;
}

GustParams ParseGusts(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"rate", "amplitude", "amplitude_spread", "duration", "horizon", "seed"});
  GustParams g;
  if (j.contains("rate")) g.rate = r.NonNegative(j["rate"], path + ".rate");
  if (j.contains("amplitude")) {
    g.amplitude = r.Number(j["amplitude"], path + ".amplitude");
    if (!(std::abs(g.amplitude) <= kMaxWindSpeed))
      r.Fail(path + ".amplitude", "expected at most " + Formatted("%g", kMaxWindSpeed) + " m/s in magnitude, got " +
                                      Formatted("%g", g.amplitude));
  }
  if (j.contains("amplitude_spread")) {
    g.amplitude_spread = r.NonNegative(j["amplitude_spread"], path + ".amplitude_spread");
    if (g.amplitude_spread > 1) r.Fail(path + ".amplitude_spread", "expected a number in [0, 1]");
  }
  if (j.contains("duration")) g.duration = r.Positive(j["duration"], path + ".duration");
  if (j.contains("horizon")) {
    g.horizon = r.Positive(j["horizon"], path + ".horizon");
    g.horizon_given = true;
  }
  // The gusts are drawn up front, rate x horizon of them: bounded, so a typo cannot ask for 1e300.
  if (g.rate * g.horizon > 1e6) r.Fail(path + ".rate", "rate x horizon must be at most 1e6 gusts");
  if (j.contains("seed")) g.seed = Seed(r, j["seed"], path + ".seed");
  return g;
}

WindSpec ParseWind(const Reader& r, const json& j, const std::string& path) {
  r.ExpectObject(j, path);
  r.CheckKeys(j, path, {"velocity", "density", "drag", "shear", "turbulence", "gusts"});
  WindSpec w;
  if (j.contains("velocity")) w.velocity = r.BoundedVector3(j["velocity"], path + ".velocity", kMaxWindSpeed, "m/s");
  if (j.contains("density")) {
    w.density = r.NonNegativeAtMost(j["density"], path + ".density", kMaxAirDensity, " kg/m^3");
  }
  if (j.contains("drag")) w.drag = r.NonNegativeAtMost(j["drag"], path + ".drag", kMaxAirDrag, " kg/(m^2 s)");
  if (j.contains("shear")) w.shear = ParseShear(r, j["shear"], path + ".shear");
  if (j.contains("turbulence")) w.turbulence = ParseTurbulence(r, j["turbulence"], path + ".turbulence");
  if (j.contains("gusts")) w.gusts = ParseGusts(r, j["gusts"], path + ".gusts");
  return w;
}

}  // namespace

std::string ResolveScenePath(const std::string& scene_path, const std::string& relative) {
  std::error_code ec;
  const fs::path rel(relative);
  if (rel.is_absolute()) return fs::is_regular_file(rel, ec) ? rel.lexically_normal().string() : "";
  const fs::path dir = fs::absolute(fs::path(scene_path), ec).parent_path();
  for (const fs::path& base : {dir, dir.parent_path(), fs::current_path(ec)}) {
    const fs::path candidate = base / rel;
    if (fs::is_regular_file(candidate, ec)) return candidate.lexically_normal().string();
  }
  return "";
}

Scene ParseScene(const std::string& text, const std::string& path, const WarningSink& warn) {
  const WarningSink sink = warn ? warn : [](const std::string& m) { std::cerr << "warning: " << m << "\n"; };
  std::error_code ec;
  const std::string abs_path = fs::absolute(fs::path(path), ec).lexically_normal().string();
  const Reader r(abs_path, sink);
  json j;
  try {
    j = ParseJsonWithComments(text);
  } catch (const json::parse_error& e) {
    // Name the line (and show it: it usually holds the key) rather than only a byte offset.
    const size_t at = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const size_t line = 1 + std::count(text.begin(), text.begin() + at, '\n');
    const size_t begin = text.rfind('\n', at == 0 ? 0 : at - 1);
    const size_t start = begin == std::string::npos ? 0 : begin + 1;
    const size_t end = text.find('\n', start);
    std::string shown = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    shown.erase(0, shown.find_first_not_of(" \t"));
    // The hint only where it applies: an empty or truncated file was told of NaN too.
    // Outside strings (closed or running to the line's end) and // comments: a name like "info"
    // is no number.
    static const std::regex kStringsAndComments(R"("(\\.|[^"\\])*("|$)|//.*)");
    std::string lower = std::regex_replace(shown, kStringsAndComments, "");
    std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
    const bool non_finite = lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos;
    throw std::runtime_error(abs_path + ":" + std::to_string(line) + ": not valid JSON near `" + shown + "`" +
                             (non_finite ? " (numbers must be finite: NaN/Infinity are not JSON)" : "") + ": " +
                             JsonErrorText(e));
  } catch (const json::exception& e) {
    // A number beyond a double ("1e400": out_of_range 406, which carries no position): named by
    // the line that holds the number the message quotes, else by the file alone.
    std::string where = abs_path;
    const std::string what = e.what();
    const size_t quote = what.find("parsing '");
    if (quote != std::string::npos) {
      const size_t from = quote + 9, to = what.find('\'', from);
      const size_t at = to == std::string::npos ? std::string::npos : text.find(what.substr(from, to - from));
      if (at != std::string::npos) where += ":" + std::to_string(1 + std::count(text.begin(), text.begin() + at, '\n'));
    }
    throw std::runtime_error(where + ": not valid JSON: " + JsonErrorText(e));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(abs_path + ": " + e.what());
  }
  r.ExpectObject(j, "(top level)");
  r.CheckKeys(j, "",
              {"frame_time", "frame_steps", "duration", "end_time", "end_frame", "timestep", "save_frames",
               "cloths", "motions", "handles", "gravity", "wind", "magic", "disable"},
              {"obstacles", "morphs", "friction", "obs_friction"});
  Scene s;
  s.path = abs_path;
  // ArcSim's two timing forms (conf.cpp): frame_time + frame_steps, ending at end_time or
  // end_frame, whichever comes first (this simulator also reads duration there); or timestep +
  // save_frames (the steps per saved frame), ending at duration.
  std::string end_key = "duration";
  const bool frame_time_form = j.contains("frame_time") || !j.contains("timestep");
  auto steps = [&](const char* key) {  // time steps per frame
    const int n = r.Integer(j[key], key);
    if (n < 1 || n > 10000) r.Fail(key, "expected an integer in 1..10000");
    return n;
  };
  if (frame_time_form) {
    if (j.contains("timestep")) r.Warn("timestep", "ignored beside frame_time, as ArcSim does");
    if (j.contains("save_frames")) r.Warn("save_frames", "ignored beside frame_time, as ArcSim does");
    if (j.contains("frame_time")) s.frame_time = r.Positive(j["frame_time"], "frame_time");
    if (j.contains("frame_steps")) s.frame_steps = steps("frame_steps");
    if (j.contains("duration")) s.duration = r.Positive(j["duration"], "duration");
    if ((j.contains("end_time") || j.contains("end_frame")) && j.contains("duration"))
      r.Warn("duration", "ignored beside end_time/end_frame, as ArcSim does");
    if (j.contains("end_time")) {
      s.duration = r.Positive(j["end_time"], "end_time");
      end_key = "end_time";
    }
    if (j.contains("end_frame")) {
      const int frames = r.Integer(j["end_frame"], "end_frame");
      if (frames < 1) r.Fail("end_frame", "expected an integer >= 1, got " + std::to_string(frames));
      if (!j.contains("end_time") || frames * s.frame_time < s.duration) {
        s.duration = frames * s.frame_time;
        end_key = "end_frame";
      }
    }
  } else {
    for (const char* key : {"frame_steps", "end_time", "end_frame"})
      if (j.contains(key)) r.Warn(key, "ignored in the timestep form, as ArcSim does (use save_frames, duration)");
    const double step = r.Positive(j["timestep"], "timestep");
    if (j.contains("save_frames")) s.frame_steps = steps("save_frames");
    s.frame_time = step * s.frame_steps;
    if (j.contains("duration")) s.duration = r.Positive(j["duration"], "duration");
  }
  // A day of simulated time at most, in at most a million frames (the frame count is an int and
  // its frames are reserved up front: 1e8 s failed in vector::reserve, 1e300 ran nothing, exit 0).
  if (!(s.duration <= 86400)) r.Fail(end_key, "expected at most 86400 s, got " + std::to_string(s.duration));
  // A frame longer than the scene (frame_time 1e300 ran 0 steps and wrote one frame, exit 0).
  if (!(s.frame_time <= s.duration))
    r.Fail(frame_time_form ? "frame_time" : "timestep",
           Formatted("a frame of %g s is longer than the scene's %g s (", s.frame_time, s.duration) + end_key + ")");
  if (!(s.duration / s.frame_time <= 1e6))
    r.Fail(frame_time_form ? "frame_time" : "timestep",
           "expected at most 1e6 frames over the duration, got " + std::to_string(s.duration / s.frame_time));
  if (j.contains("motions")) {
    // Moving handles are not simulated: a motion file ({"motfile": ...}) or a list is kept as given.
    if (j["motions"].is_object()) {
      r.Warn("motions", "a motion file is not read here (moving handles are not simulated)");
      s.motions.push_back(j["motions"]);
    } else {
      r.ExpectArray(j["motions"], "motions");
      for (const auto& m : j["motions"]) s.motions.push_back(m);
    }
  }
  // ArcSim's `disable`: modules switched off. Those this simulator has are switched off too; the
  // others it never runs.
  std::set<std::string> disabled;
  if (j.contains("disable")) {
    const json& d = j["disable"].is_string() ? json::array({j["disable"]}) : j["disable"];
    r.ExpectArray(d, "disable");
    for (size_t i = 0; i < d.size(); ++i) {
      const std::string name = r.String(d[i], Reader::Index("disable", i));
      if (name == "proximity") {
        s.self_collision = false;
      } else if (name == "collision") {
        s.crossing_correction = false;
      } else if (name == "strainlimiting" || name == "remeshing") {
        disabled.insert(name);
      } else if (name == "popfilter" || name == "plasticity" || name == "separation") {
        r.Warn(Reader::Index("disable", i), "'" + name + "': a module this simulator does not have");
      } else if (name == "physics") {
        r.Fail(Reader::Index("disable", i), "'physics' cannot be switched off here (the cloth would not move)");
      } else {
        r.Fail(Reader::Index("disable", i), "unknown module '" + name + "' (ArcSim's: proximity, physics, "
                                            "strainlimiting, collision, remeshing, separation, popfilter, "
                                            "plasticity)");
      }
    }
  }
  if (!j.contains("cloths")) r.Fail("cloths", "missing (at least one cloth)");
  r.ExpectArray(j["cloths"], "cloths");
  if (j["cloths"].empty()) r.Fail("cloths", "expected at least one cloth");
  for (size_t i = 0; i < j["cloths"].size(); ++i) {
    s.cloths.push_back(ParseCloth(r, j["cloths"][i], Reader::Index("cloths", i)));
    if (disabled.count("remeshing")) s.cloths.back().remeshing.present = false;
    if (disabled.count("strainlimiting"))
      for (SceneMaterial& m : s.cloths.back().materials) m.has_strain_limits = false;
  }
  if (j.contains("handles")) {
    r.ExpectArray(j["handles"], "handles");
    for (size_t i = 0; i < j["handles"].size(); ++i) {
      const std::string p = Reader::Index("handles", i);
      s.handles.push_back(ParseHandle(r, j["handles"][i], p, static_cast<int>(s.motions.size())));
      if (s.handles.back().cloth < 0 || s.handles.back().cloth >= static_cast<int>(s.cloths.size())) {
        r.Fail(p + ".cloth", "cloth index out of range (" + std::to_string(s.cloths.size()) + " cloths)");
      }
    }
  }
  if (j.contains("gravity")) s.gravity = r.BoundedVector3(j["gravity"], "gravity", kMaxAcceleration, "m/s^2");
  if (j.contains("wind")) s.wind = ParseWind(r, j["wind"], "wind");
  // Gusts are drawn up to their horizon and none come after it: unless the scene sets one,
  // Simulate draws them over the whole run; a horizon set shorter than the scene says so.
  const GustParams& gusts = s.wind.gusts;
  if (gusts.rate > 0 && gusts.amplitude != 0 && gusts.horizon_given && gusts.horizon < s.duration) {
    r.Warn("wind.gusts.horizon", "gusts end at " + std::to_string(gusts.horizon) + " s, before the scene's end (" +
                                     std::to_string(s.duration) + " s)");
  }
  if (gusts.rate * std::max(s.duration, gusts.horizon) > 1e6)
    r.Fail("wind.gusts.rate", "rate x duration must be at most 1e6 gusts (they are drawn up front)");
  if (j.contains("magic")) {
    const json& m = j["magic"];
    r.ExpectObject(m, "magic");
    r.CheckKeys(m, "magic", {"repulsion_thickness", "collision_stiffness"},
                {"fixed_high_res_mesh", "handle_stiffness", "projection_thickness",
                 "edge_flip_threshold", "rib_stiffening", "combine_tensors", "preserve_creases"});
    if (m.contains("repulsion_thickness")) {
      // At most 0.1 m (ArcSim's default is 1 mm, ours 10 mm): 10, a typo for 10e-3, blew the
      // simulation up naming nothing, and 1e200 crashed it.
      s.magic.repulsion_thickness = r.NonNegativeAtMost(m["repulsion_thickness"], "magic.repulsion_thickness", 0.1, " m");
    }
    if (m.contains("collision_stiffness")) {
      // At most 1e12 (ArcSim's default 1e9).
      s.magic.collision_stiffness = r.NonNegativeAtMost(m["collision_stiffness"], "magic.collision_stiffness", 1e12);
    }
  }
  return s;
}

Scene LoadScene(const std::string& path, const WarningSink& warn) {
  // A folder, an unreadable or an empty file named as such (a folder read as an empty scene).
  return ParseScene(ReadTextFile(path, "a scene file"), path, warn);
}

}  // namespace clothwind::sim
