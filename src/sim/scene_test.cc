#include "sim/scene.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <fstream>
#include <limits>

#include <unistd.h>

#include <gtest/gtest.h>

#include "sim/scene_builder.h"

namespace clothwind::sim {
namespace {

namespace fs = std::filesystem;

// Run outside ctest, "." failed 15 tests with "./config/scenes/flag.json: cannot open".
std::string SourceDir() {
  const char* s = std::getenv("CLOTHWIND_SOURCE_DIR");
  if (!s) throw std::runtime_error("CLOTHWIND_SOURCE_DIR is not set (ctest sets it to the source tree)");
  return s;
}

std::string SharedDir() {
  const char* s = std::getenv("CLOTHWIND_SHARED_DIR");
  return s ? s : "";
}

struct Warnings {
  std::vector<std::string> list;
  WarningSink sink() {
    return [this](const std::string& m) { list.push_back(m); };
  }
};

// Expects `f` to throw std::runtime_error whose message contains every one of `parts`.
template <typename F>
void ExpectErrorNaming(F f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "expected an error naming " << parts.front();
  } catch (const std::runtime_error& e) {
    for (const auto& p : parts) {
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos)
          << "error \"" << e.what() << "\" does not name \"" << p << "\"";
    }
  }
}

// A scratch ArcSim-like tree: <root>/conf/*.json, <root>/meshes/*.obj.
class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("clothwind_scene_test_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(root_ / "conf");
    fs::create_directories(root_ / "meshes");
    Write("meshes/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
    material_ = SourceDir() + "/config/materials/camel-ponte-roma.json";
  }
  void TearDown() override { fs::remove_all(root_); }

  std::string Write(const std::string& rel, const std::string& text) {
    const fs::path p = root_ / rel;
    std::ofstream(p) << text;
    return p.string();
  }
  // A valid scene with `extra` spliced into the top-level object and `material` as the entry.
  std::string SceneText(const std::string& extra = "", const std::string& cloth_extra = "",
                        const std::string& handles = "[0, 3]") const {
    return "{\n"
           "  \"frame_time\": 0.04, \"frame_steps\": 4, \"duration\": 1,\n"
           "  \"cloths\": [{\"mesh\": \"meshes/quad.obj\", " + cloth_extra +
           "    \"materials\": [{\"data\": \"" + material_ + "\", \"thicken\": 2}]}],\n"
           "  \"handles\": [{\"nodes\": " + handles + "}],\n"
           "  \"gravity\": [0, 0, -9.8]" + extra + "\n}\n";
  }

  // `text` with its one `from` replaced by `to` (a key changed in place, not given twice).
  static std::string Replace(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from << " is not unique";
    return at == std::string::npos ? text : text.replace(at, from.size(), to);
  }

  fs::path root_;
  std::string material_;
};

TEST(LoadScene, ReadsArcSimsOwnFlagScene) {
  const std::string shared = SharedDir();
  const std::string path = shared + "/arcsim/conf/flag.json";
  if (shared.empty() || !fs::exists(path)) GTEST_SKIP() << "no " << path;
  Warnings w;
  const Scene s = LoadScene(path, w.sink());
  EXPECT_TRUE(w.list.empty()) << w.list.front();
  EXPECT_DOUBLE_EQ(s.frame_time, 0.04);
  EXPECT_EQ(s.frame_steps, 8);
  EXPECT_DOUBLE_EQ(s.time_step(), 0.005);
  EXPECT_DOUBLE_EQ(s.duration, 20);
  ASSERT_EQ(s.cloths.size(), 1u);
  EXPECT_EQ(fs::path(s.cloths[0].mesh), fs::path(shared + "/arcsim/meshes/flag.obj").lexically_normal());
  EXPECT_DOUBLE_EQ(s.cloths[0].transform.rotate_deg, 120);
  EXPECT_EQ(s.cloths[0].transform.rotate_axis, Eigen::Vector3d(1, 1, 1));
  ASSERT_EQ(s.cloths[0].materials.size(), 1u);
  EXPECT_DOUBLE_EQ(s.cloths[0].materials[0].thicken, 2);
  EXPECT_DOUBLE_EQ(s.cloths[0].materials[0].strain_min, 0.95);
  EXPECT_DOUBLE_EQ(s.cloths[0].materials[0].strain_max, 1.05);
  EXPECT_DOUBLE_EQ(s.cloths[0].remeshing.size_min, 0.02);
  EXPECT_DOUBLE_EQ(s.cloths[0].remeshing.size_max, 0.5);
  ASSERT_EQ(s.handles.size(), 1u);
  EXPECT_EQ(s.handles[0].nodes, (std::vector<int>{0, 3}));
  EXPECT_EQ(s.gravity, Eigen::Vector3d(0, 0, -9.8));
  EXPECT_EQ(s.wind.velocity, Eigen::Vector3d(10, 0, 0));
  EXPECT_DOUBLE_EQ(s.wind.density, 1.0);  // ArcSim's defaults
  EXPECT_DOUBLE_EQ(s.wind.drag, 0.0);
  EXPECT_DOUBLE_EQ(s.magic.repulsion_thickness, 0.01);
  EXPECT_DOUBLE_EQ(s.magic.collision_stiffness, 1e6);
}

TEST(BuildScene, ArcSimFlagHangsInTheYZPlaneWithTheHoistOnTheZAxis) {
  const std::string path = SharedDir() + "/arcsim/conf/flag.json";
  if (SharedDir().empty() || !fs::exists(path)) GTEST_SKIP() << "no " << path;
  const SceneSetup setup = BuildScene(LoadScene(path));
  ASSERT_EQ(setup.cloths.size(), 1u);
  const ClothSetup& c = setup.cloths[0];
  EXPECT_EQ(c.original_vertices, 58);
  EXPECT_NEAR(c.max_edge, 0.2, 1e-12);  // 0.4 of the size range's upper end, 0.5 m
  EXPECT_LE(MaxEdgeLength(c.mesh), 0.2 + 1e-9);
  // Refined (485 vertices: uniform to 0.5 m, then the longer edges split), fewer than the
  // uniform refinement to 0.25 m (811 vertices, whose longest edge is still longer).
  EXPECT_GT(c.mesh.V.rows(), 400);
  const Mesh uniform = BuildScene(LoadScene(path), BuildOptions{0.25}).cloths[0].mesh;
  EXPECT_LT(c.mesh.V.rows(), uniform.V.rows());
  EXPECT_GT(MaxEdgeLength(uniform), MaxEdgeLength(c.mesh));
  EXPECT_NEAR(SurfaceArea(c.mesh), 6.0, 1e-9);
  EXPECT_NEAR(RestArea(c.mesh), 6.0, 1e-9);
  EXPECT_LT(c.mesh.V.col(0).cwiseAbs().maxCoeff(), 1e-9);  // x = 0: the y-z plane
  EXPECT_LT((c.mesh.V.row(0) - Eigen::RowVector3d(0, 0, 0)).norm(), 1e-9);
  EXPECT_LT((c.mesh.V.row(3) - Eigen::RowVector3d(0, 0, 2)).norm(), 1e-9);  // hoist top
  EXPECT_LT((c.mesh.V.row(1) - Eigen::RowVector3d(0, 3, 0)).norm(), 1e-9);  // fly bottom
  EXPECT_EQ(c.options.handles, (std::vector<int>{0, 3}));
  EXPECT_NEAR(c.material.density, 2 * 0.284, 1e-12);
  EXPECT_DOUBLE_EQ(c.options.dt, 0.005);
  EXPECT_DOUBLE_EQ(c.options.strain_min, 0.95);
  EXPECT_DOUBLE_EQ(c.options.strain_max, 1.05);
  EXPECT_DOUBLE_EQ(c.options.wind_density, 1.0);
  EXPECT_EQ(setup.wind.velocity, Eigen::Vector3d(10, 0, 0));
}

TEST(LoadScene, ReadsOurFlagAndClothScenes) {
  Warnings w;
  const Scene flag = LoadScene(SourceDir() + "/config/scenes/flag.json", w.sink());
  const Scene cloth = LoadScene(SourceDir() + "/config/scenes/cloth.json", w.sink());
  EXPECT_TRUE(w.list.empty()) << w.list.front();
  EXPECT_EQ(flag.gravity, Eigen::Vector3d(0, 0, -9.81));  // Listing 1
  EXPECT_EQ(cloth.wind.velocity.z(), 0.0);                // Listing 2: horizontal wind
  const SceneSetup f = BuildScene(flag);
  EXPECT_NEAR(f.cloths[0].material.density, 2 * 0.135, 1e-12);  // Listing 3 x thicken 2
  EXPECT_NEAR(SurfaceArea(f.cloths[0].mesh), 6.0, 1e-9);
  EXPECT_LT((f.cloths[0].mesh.V.row(3) - Eigen::RowVector3d(0, 0, 2)).norm(), 1e-9);
  BuildOptions two_steps;
  two_steps.frame_steps = 2;
  const SceneSetup f2 = BuildScene(flag, two_steps);
  EXPECT_EQ(f2.scene.frame_steps, 2);
  EXPECT_DOUBLE_EQ(f2.cloths[0].options.dt, 0.02);
  EXPECT_DOUBLE_EQ(f.cloths[0].options.dt, 0.005);
  const SceneSetup c = BuildScene(cloth, BuildOptions{0.25});
  EXPECT_NEAR(SurfaceArea(c.cloths[0].mesh), 1.0, 1e-9);
  EXPECT_LE(MaxEdgeLength(c.cloths[0].mesh), 0.25 + 1e-9);
  // Handles 2 and 3 are the top corners (z = 1).
  for (int n : c.cloths[0].options.handles) EXPECT_NEAR(c.cloths[0].mesh.V(n, 2), 1.0, 1e-9);
}

// The split length is 0.4 size_max, never below size_min: [0.3, 0.5] m split to 0.2 m, finer
// than ArcSim itself refines.
TEST(BuildScene, TheDefaultResolutionStaysWithinTheRemeshingSizeRange) {
  SceneRemeshing r;
  r.present = true;
  r.size_min = 0.02;
  r.size_max = 0.5;
  EXPECT_DOUBLE_EQ(DefaultMaxEdge(r), 0.2);
  r.size_min = 0.3;
  EXPECT_DOUBLE_EQ(DefaultMaxEdge(r), 0.3);
  EXPECT_DOUBLE_EQ(DefaultUniformEdge(r), 0.5);
  r.present = false;
  EXPECT_EQ(DefaultMaxEdge(r), 0.0);
}

TEST(BuildScene, RefusesANegativeOrNotANumberEdgeLength) {
  const Scene flag = LoadScene(SourceDir() + "/config/scenes/flag.json");
  for (double bad : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    for (int which = 0; which < 2; ++which) {
      BuildOptions o;
      (which == 0 ? o.max_edge : o.split_edge) = bad;
      try {
        BuildScene(flag, o);
        ADD_FAILURE() << "edge length " << bad << " accepted";
      } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(which == 0 ? "max_edge" : "split_edge"), std::string::npos) << e.what();
      }
    }
  }
}

TEST_F(SceneFiles, ValidSceneWithCommentsTransformAndExtensions) {
  Warnings w;
  const std::string path = Write(
      "conf/s.json",
      "// comment line\n" +
          SceneText(",\n /* wind with our extensions */ \"wind\": {\"velocity\": [2, 0, 0],"
                    " \"drag\": 0.5, \"turbulence\": {\"intensity\": 0.1, \"length_scale\": 30,"
                    " \"seed\": 4}, \"gusts\": {\"rate\": 0.1, \"amplitude\": 1.5},"
                    " \"shear\": {\"profile\": \"log\", \"roughness\": 0.05, \"ground_z\": -4.6}}",
                    "\"transform\": {\"translate\": [1, 2, 3], \"rotate\": [90, 0, 0, 1],"
                    " \"scale\": 2},"));
  const Scene s = LoadScene(path, w.sink());
  EXPECT_TRUE(w.list.empty());
  EXPECT_DOUBLE_EQ(s.wind.drag, 0.5);
  EXPECT_DOUBLE_EQ(s.wind.turbulence.intensity, 0.1);
  EXPECT_EQ(s.wind.turbulence.seed, 4u);
  EXPECT_EQ(s.wind.shear.kind, ShearProfile::Kind::kLog);
  EXPECT_DOUBLE_EQ(s.wind.shear.ground_z, -4.6);
  // Found in the scene folder's parent (ArcSim's root), as ArcSim's relative paths are.
  EXPECT_EQ(fs::path(s.cloths[0].mesh), (root_ / "meshes/quad.obj").lexically_normal());
  const SceneSetup setup = BuildScene(s);
  const Mesh& m = setup.cloths[0].mesh;
  // x -> translate + Rz(90) (2 x): (1, 0, 0) -> (1, 2 + 2, 3).
  EXPECT_LT((m.V.row(1) - Eigen::RowVector3d(1, 4, 3)).norm(), 1e-9);
  EXPECT_NEAR(RestArea(m), 4.0, 1e-9);  // rest shape scaled too
  // A transform that puts the cloth beyond 100 m is named as the transform's: it was the OBJ's
  // "vertex 2 has a non-finite position" (one below the OBJ's own number) at scale 1e308, or a
  // degenerate face at 1e300 (scales past 1e4 are refused by the reader now: SceneFiles's
  // PhysicallyAbsurdMagnitudes).
  for (const std::string transform : {"\"scale\": 1e4", "\"translate\": [0, 150, 0]"}) {
    const std::string far = Write("conf/far.json", SceneText("", "\"transform\": {" + transform + "},"));
    ExpectErrorNaming([&] { BuildScene(LoadScene(far)); }, {far, "cloths[0].transform", "within +-100 m"});
  }
}

TEST_F(SceneFiles, UnknownKeysWarnNamingKeyAndFile) {
  Warnings w;
  const std::string path = Write("conf/s.json", SceneText(", \"gravityy\": [0, 0, 1], \"obstacles\": []"));
  LoadScene(path, w.sink());
  ASSERT_EQ(w.list.size(), 2u);
  EXPECT_NE(w.list[0].find("gravityy"), std::string::npos);
  EXPECT_NE(w.list[0].find("unknown key"), std::string::npos);
  EXPECT_NE(w.list[0].find(path), std::string::npos);
  EXPECT_NE(w.list[1].find("obstacles"), std::string::npos);
  EXPECT_NE(w.list[1].find("not supported"), std::string::npos);
}

// ArcSim's cloths[i].velocity: every node starts at linear + angular x (x - origin), after the
// transform (ArcSim's apply_velocity). Numbers worked by hand for the unit quad.
TEST_F(SceneFiles, AClothsInitialVelocityIsArcSimsRigidMotion) {
  Warnings w;
  const std::string path = Write("conf/v.json", SceneText("", "\"velocity\": {\"linear\": [1, 2, 0], "
                                                              "\"angular\": [0, 0, 2], \"origin\": [0.5, 0.5, 0]},"));
  const SceneSetup setup = BuildScene(LoadScene(path, w.sink()));
  EXPECT_TRUE(w.list.empty()) << w.list.front();
  const Eigen::MatrixX3d& vel = setup.cloths[0].velocities;
  ASSERT_EQ(vel.rows(), 4);
  // (0,0,0): r = (-0.5,-0.5,0), w x r = (1,-1,0); (1,0,0): r = (0.5,-0.5,0), w x r = (1,1,0);
  // (1,1,0): (-1,1,0); (0,1,0): (-1,-1,0). Nodes 0 and 3, the scene's handles, start still.
  const Eigen::Matrix<double, 4, 3> expected = (Eigen::Matrix<double, 4, 3>() << 0, 0, 0, 2, 3, 0, 0, 3, 0, 0, 0, 0).finished();
  EXPECT_LT((vel - expected).cwiseAbs().maxCoeff(), 1e-12) << vel;
  // No velocity: still.
  EXPECT_TRUE(BuildScene(LoadScene(Write("conf/still.json", SceneText()))).cloths[0].velocities.isZero(0));
  // The wind's array form is not ArcSim's for a cloth: refused, saying how to write it.
  const std::string array = Write("conf/array.json", SceneText("", "\"velocity\": [1, 0, 0],"));
  ExpectErrorNaming([&] { LoadScene(array); }, {array, "cloths[0].velocity", "{\"linear\": [vx, vy, vz]}"});
  // Bounds: each part, and the speed a spin about a far origin gives a node.
  const std::string fast = Write("conf/fast.json", SceneText("", "\"velocity\": {\"linear\": [2000, 0, 0]},"));
  ExpectErrorNaming([&] { LoadScene(fast); }, {fast, "cloths[0].velocity.linear", "at most 1000 m/s"});
  const std::string spin = Write("conf/spin.json", SceneText("", "\"velocity\": {\"angular\": [0, 0, 10], "
                                                                 "\"origin\": [300, 0, 0]},"));
  ExpectErrorNaming([&] { BuildScene(LoadScene(spin)); }, {spin, "cloths[0].velocity", "vertex 2 at 2990.02 m/s", "at most the simulator's 1000 m/s"});
  // After the transform and the refinement, about a world point: the quad turned 90 deg about z
  // and moved to (1, 2, 3), split to 0.2 m edges, spinning at 2 rad/s about (1, 2, 3). Its OBJ
  // vertex 1, (1, 0, 0), is at (1, 3, 3): r = (0, 1, 0), w x r = (-2, 0, 0); vertex 2, (1, 1, 0),
  // at (0, 3, 3): r = (-1, 1, 0), w x r = (-2, -2, 0). Pinned nodes (0 and 3) start still.
  const std::string moved = Write(
      "conf/moved.json", SceneText("", "\"transform\": {\"translate\": [1, 2, 3], \"rotate\": [90, 0, 0, 1]}, "
                                       "\"velocity\": {\"angular\": [0, 0, 2], \"origin\": [1, 2, 3]}, "
                                       "\"remeshing\": {\"size\": [0.2, 0.5]},"));
  const SceneSetup m = BuildScene(LoadScene(moved));
  const Eigen::MatrixX3d& mv = m.cloths[0].velocities;
  ASSERT_GT(m.cloths[0].mesh.V.rows(), 20) << "the quad must be refined for this test";
  ASSERT_EQ(mv.rows(), m.cloths[0].mesh.V.rows());
  EXPECT_LT((mv.row(1) - Eigen::RowVector3d(-2, 0, 0)).norm(), 1e-9) << mv.row(1);
  EXPECT_LT((mv.row(2) - Eigen::RowVector3d(-2, -2, 0)).norm(), 1e-9) << mv.row(2);
  EXPECT_TRUE(mv.row(0).isZero(0) && mv.row(3).isZero(0)) << mv.row(0) << " " << mv.row(3);
  for (Eigen::Index i = 4; i < mv.rows(); ++i) {  // the refinement's new vertices spin with the cloth
    const Eigen::Vector3d r = m.cloths[0].mesh.V.row(i).transpose() - Eigen::Vector3d(1, 2, 3);
    EXPECT_LT((mv.row(i).transpose() - Eigen::Vector3d(-2 * r.y(), 2 * r.x(), 0)).norm(), 1e-9) << i;
  }
  // A pinned node's speed does not count: spun fast about (1, 0.5, 0), the pinned corners would
  // move at 1118 m/s, the free ones move at 500.
  const std::string pinned_fast = Write("conf/pinned_fast.json", SceneText("", "\"velocity\": {\"angular\": [0, 0, 1000], "
                                                                               "\"origin\": [1, 0.5, 0]},"));
  const SceneSetup pf = BuildScene(LoadScene(pinned_fast));
  EXPECT_NEAR(pf.cloths[0].velocities.rowwise().norm().maxCoeff(), 500.0, 1e-9);
  Warnings typo;
  LoadScene(Write("conf/typo.json", SceneText("", "\"velocity\": {\"linaer\": [1, 0, 0]},")), typo.sink());
  ASSERT_EQ(typo.list.size(), 1u);
  EXPECT_NE(typo.list[0].find("cloths[0].velocity.linaer: unknown key"), std::string::npos) << typo.list[0];
}

TEST_F(SceneFiles, ArcSimsTimingFormsEndAtTheFirstLimitReached) {
  auto scene = [&](const std::string& name, const std::string& timing) {
    return Write("conf/" + name, "{" + timing + ", \"cloths\": [{\"mesh\": \"meshes/quad.obj\", \"materials\": "
                                 "[{\"data\": \"" + material_ + "\"}]}]}");
  };
  // ArcSim's other form: a time step, the steps per saved frame, and the duration.
  Warnings w;
  const Scene a = LoadScene(scene("a.json", "\"timestep\": 0.005, \"save_frames\": 8, \"duration\": 2"), w.sink());
  EXPECT_TRUE(w.list.empty()) << w.list[0];
  EXPECT_DOUBLE_EQ(a.time_step(), 0.005);  // was the default frame time 0.04: 8x too coarse
  EXPECT_EQ(a.frame_steps, 8);
  EXPECT_DOUBLE_EQ(a.frame_time, 0.04);
  EXPECT_DOUBLE_EQ(a.duration, 2);
  // end_time and end_frame: whichever comes first (end_frame alone used to win).
  EXPECT_NEAR(LoadScene(scene("b.json", "\"frame_time\": 0.04, \"end_time\": 0.08, \"end_frame\": 1000")).duration,
              0.08, 1e-12);
  EXPECT_NEAR(LoadScene(scene("c.json", "\"frame_time\": 0.04, \"end_time\": 5, \"end_frame\": 10")).duration, 0.4,
              1e-12);
  // A limit out of range is named by the key that set it.
  const std::string d = scene("d.json", "\"frame_time\": 0.04, \"end_frame\": 3000000");
  ExpectErrorNaming([&] { LoadScene(d); }, {d, "end_frame", "at most 86400 s"});
  // A number beyond a double is named by file and line (it was nlohmann's bare out_of_range).
  const std::string e = Write("conf/e.json", Replace(SceneText(), "\"duration\": 1", "\"duration\": 1e400"));
  ExpectErrorNaming([&] { LoadScene(e); }, {e + ":2: not valid JSON", "1e400"});
  // A frame longer than the scene: 1e300 ran no step and wrote one frame, exit 0.
  const std::string f = scene("f.json", "\"frame_time\": 1e300, \"duration\": 20");
  ExpectErrorNaming([&] { LoadScene(f); }, {f, "frame_time", "a frame of 1e+300 s is longer than the scene's 20 s"});
  // An empty file, or a folder, is named as such (an empty scene was told NaN is not JSON).
  const std::string empty = Write("conf/empty.json", "\n");
  ExpectErrorNaming([&] { LoadScene(empty); }, {empty, "the file is empty"});
  ExpectErrorNaming([&] { LoadScene((root_ / "conf").string()); }, {"conf: a folder, expected a JSON file"});
}

TEST_F(SceneFiles, DisabledArcSimModulesAreSwitchedOffOrNamed) {
  Warnings w;
  std::string text = SceneText(", \"disable\": [\"strainlimiting\", \"remeshing\", \"proximity\", \"popfilter\"]",
                               "\"remeshing\": {\"size\": [0.1, 0.3]},");
  text.replace(text.find("\"thicken\": 2"), 12, "\"thicken\": 2, \"strain_limits\": [0.95, 1.05]");
  const std::string path = Write("conf/s.json", text);
  const Scene s = LoadScene(path, w.sink());
  ASSERT_EQ(w.list.size(), 1u);
  EXPECT_NE(w.list[0].find("disable[3]"), std::string::npos) << w.list[0];
  EXPECT_FALSE(s.cloths[0].materials[0].has_strain_limits);
  EXPECT_FALSE(s.cloths[0].remeshing.present);
  const SceneSetup setup = BuildScene(s);
  EXPECT_FALSE(setup.cloths[0].options.self_collision);
  EXPECT_EQ(setup.cloths[0].options.strain_min, SimOptions().strain_min);
  EXPECT_EQ(setup.cloths[0].options.strain_max, SimOptions().strain_max);
  EXPECT_EQ(setup.cloths[0].mesh.V.rows(), 4);  // not refined
  // Without the list the same scene keeps them.
  const Scene kept = LoadScene(Write("conf/kept.json", SceneText("", "\"remeshing\": {\"size\": [0.1, 0.3]},")));
  EXPECT_TRUE(kept.cloths[0].remeshing.present);
  EXPECT_TRUE(BuildScene(kept).cloths[0].options.self_collision);
  const Scene collision = LoadScene(Write("conf/col.json", SceneText(", \"disable\": [\"collision\"]")));
  EXPECT_EQ(BuildScene(collision).cloths[0].options.crossing_sweeps, 0);
  const std::string bad = Write("conf/bad.json", SceneText(", \"disable\": [\"colision\"]"));
  ExpectErrorNaming([&] { LoadScene(bad); }, {bad, "disable[0]", "unknown module 'colision'"});
}

TEST_F(SceneFiles, ArcSimScenesThisSimulatorReadsDifferentlySaySo) {
  // A remeshing block without size (ArcSim's default [-inf, inf] refines nothing), motions from a
  // file, and a handle by label: the first two load with a warning, the last is named.
  Warnings w;
  const Scene s = LoadScene(Write("conf/s.json", SceneText(", \"motions\": {\"motfile\": \"m.txt\", \"fps\": 30}",
                                                           "\"remeshing\": {\"refine_angle\": 0.3},")),
                            w.sink());
  ASSERT_EQ(w.list.size(), 2u);
  EXPECT_NE(w.list[0].find("motions"), std::string::npos) << w.list[0];
  EXPECT_NE(w.list[1].find("remeshing.size"), std::string::npos) << w.list[1];
  EXPECT_FALSE(s.cloths[0].remeshing.present);
  std::string labelled = SceneText();
  labelled.replace(labelled.find("\"nodes\": [0, 3]"), 15, "\"label\": 1");
  const std::string label = Write("conf/label.json", labelled);
  ExpectErrorNaming([&] { LoadScene(label); }, {label, "handles[0].label", "not supported"});
  // ArcSim's own handle keys are said as ArcSim's, not as typos ("unknown key").
  Warnings faded;
  std::string fade = SceneText();
  fade.replace(fade.find("\"nodes\": [0, 3]"), 15, "\"nodes\": [0, 3], \"fade_time\": 1");
  LoadScene(Write("conf/fade.json", fade), faded.sink());
  ASSERT_EQ(faded.list.size(), 1u);
  EXPECT_NE(faded.list[0].find("handles[0].fade_time: ArcSim key not supported"), std::string::npos) << faded.list[0];
}

TEST_F(SceneFiles, WrongTypesNameTheJsonPathAndFile) {
  const std::string a = Write("conf/a.json", SceneText(", \"wind\": {\"velocity\": [1, \"x\", 0]}"));
  ExpectErrorNaming([&] { LoadScene(a); }, {a, "wind.velocity[1]", "expected a number"});
  std::string text = SceneText();
  text.replace(text.find("\"" + material_ + "\""), material_.size() + 2, "42");
  const std::string b = Write("conf/b.json", text);
  ExpectErrorNaming([&] { LoadScene(b); }, {b, "cloths[0].materials[0].data", "expected a string"});
  const std::string c = Write("conf/c.json", Replace(SceneText(), "\"frame_steps\": 4", "\"frame_steps\": 2.5"));
  ExpectErrorNaming([&] { LoadScene(c); }, {c, "frame_steps", "expected an integer, got 2.5"});
  // A whole number with a point is the integer, as ArcSim's reader takes it.
  const std::string whole = Write("conf/whole.json", Replace(SceneText(), "\"frame_steps\": 4", "\"frame_steps\": 8.0"));
  EXPECT_EQ(LoadScene(whole).frame_steps, 8);
  const std::string d = Write("conf/d.json", SceneText("", "\"transform\": {\"rotate\": [90, 1, 1]},"));
  ExpectErrorNaming([&] { LoadScene(d); }, {d, "cloths[0].transform.rotate", "4 numbers"});
  const std::string e = Write("conf/e.json", "{\"frame_time\": 0.04}");
  ExpectErrorNaming([&] { LoadScene(e); }, {e, "cloths", "missing"});
  const std::string f = Write("conf/f.json", SceneText(", \"wind\": {\"density\": -1}"));
  ExpectErrorNaming([&] { LoadScene(f); }, {f, "wind.density", ">= 0"});
  // Integers get<int> would wrap (4294967297 read as 1) and counts or spans that would allocate
  // without bound or overflow the frame count: each refused naming its key.
  const std::string g = Write("conf/g.json", Replace(SceneText(), "\"frame_steps\": 4", "\"frame_steps\": 4294967297"));
  ExpectErrorNaming([&] { LoadScene(g); }, {g, "frame_steps", "int's range", "4294967297"});
  const std::string h = Write("conf/h.json", Replace(SceneText(), "\"frame_steps\": 4", "\"frame_steps\": 2000000000"));
  ExpectErrorNaming([&] { LoadScene(h); }, {h, "frame_steps", "1..10000"});
  const std::string i = Write("conf/i.json", Replace(SceneText(), "\"duration\": 1,", "\"duration\": 1e8,"));
  ExpectErrorNaming([&] { LoadScene(i); }, {i, "duration", "at most 86400 s"});
  const std::string k = Write("conf/k.json", SceneText(", \"wind\": {\"turbulence\": {\"modes\": 2000000000}}"));
  ExpectErrorNaming([&] { LoadScene(k); }, {k, "wind.turbulence.modes", "1..10000"});
  const std::string l = Write("conf/l.json", SceneText(", \"wind\": {\"gusts\": {\"rate\": 1e300}}"));
  ExpectErrorNaming([&] { LoadScene(l); }, {l, "wind.gusts.rate", "at most 1e6 gusts"});
}

TEST_F(SceneFiles, PhysicallyAbsurdMagnitudesAreRefusedNamingFileAndField) {
  // gravity 1e200, thicken 1e300, wind 1e300: each loaded, the solve's numbers overflowed, and the
  // scene ran to its end (exit 0) with a cloth that never moved. Each is refused by its key, and
  // the largest sane values still load.
  struct Case {
    std::string name, text, key, says;
  };
  const std::vector<Case> cases = {
      {"gravity", Replace(SceneText(), "[0, 0, -9.8]", "[0, 0, -1e200]"), "gravity", "at most 1000 m/s^2"},
      {"gravity_norm", Replace(SceneText(), "[0, 0, -9.8]", "[600, 600, -600]"), "gravity", "at most 1000 m/s^2"},
      {"thicken", Replace(SceneText(), "\"thicken\": 2", "\"thicken\": 1e300"), "cloths[0].materials[0].thicken",
       "(0, 1e+06]"},
      {"density_mult", Replace(SceneText(), "\"thicken\": 2", "\"density_mult\": 2e6"),
       "cloths[0].materials[0].density_mult", "(0, 1e+06]"},
      {"stretching_mult", Replace(SceneText(), "\"thicken\": 2", "\"stretching_mult\": 1e7"),
       "cloths[0].materials[0].stretching_mult", "(0, 1e+06]"},
      {"bending_mult", Replace(SceneText(), "\"thicken\": 2", "\"bending_mult\": 1e7"),
       "cloths[0].materials[0].bending_mult", "(0, 1e+06]"},
      {"damping", Replace(SceneText(), "\"thicken\": 2", "\"damping\": 1e300"), "cloths[0].materials[0].damping",
       "[0, 1000] s"},
      {"wind", SceneText(", \"wind\": {\"velocity\": [1e300, 0, 0]}"), "wind.velocity", "at most 1000 m/s"},
      {"gusts", SceneText(", \"wind\": {\"gusts\": {\"amplitude\": -2000}}"), "wind.gusts.amplitude", "1000 m/s"},
      {"turbulence", SceneText(", \"wind\": {\"turbulence\": {\"intensity\": 1e300}}"), "wind.turbulence.intensity",
       "[0, 10]"},
      // (1e-300 m: the field's wavenumbers overflowed, "non-finite force" steps later.)
      {"turbulence_length", SceneText(", \"wind\": {\"turbulence\": {\"length_scale\": 1e-300}}"),
       "wind.turbulence.length_scale", "0.01..10000 m"},
      // A profile without its ground: z 0 was taken as the ground, the flag's foot, and the flag
      // hung in almost no wind.
      {"shear_ground", SceneText(", \"wind\": {\"velocity\": [3, 0, 0], \"shear\": {}}"), "wind.shear.ground_z",
       "required with a profile"},
      {"air", SceneText(", \"wind\": {\"density\": 1e300}"), "wind.density", "kg/m^3"},
      // 1e200 crashed the simulator (a NaN curvature cast to an index); 10, a typo for 10e-3,
      // blew it up naming nothing.
      {"repulsion_thickness", SceneText(", \"magic\": {\"repulsion_thickness\": 10}"), "magic.repulsion_thickness",
       "[0, 0.1] m"},
      {"collision_stiffness", SceneText(", \"magic\": {\"collision_stiffness\": 1e200}"), "magic.collision_stiffness",
       "[0, 1e+12]"},
      // 1e-300 made every face "degenerate", blamed on the OBJ.
      {"scale", SceneText("", "\"transform\": {\"scale\": 1e-300}, "), "cloths[0].transform.scale",
       "[1e-4, 1e4], got 1e-300"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = Write("conf/" + c.name + ".json", c.text);
    ExpectErrorNaming([&] { LoadScene(path); }, {path, c.key, c.says});
  }
  const std::string edge = Write("conf/edge.json", Replace(Replace(SceneText(", \"wind\": {\"velocity\": [0, 0, 1000], "
                                                                            "\"gusts\": {\"amplitude\": 1000}}"),
                                                                  "[0, 0, -9.8]", "[0, 0, -1000]"),
                                                          "\"thicken\": 2", "\"thicken\": 1e6, \"density_mult\": 1e-6"));
  const Scene s = LoadScene(edge);
  EXPECT_EQ(s.gravity.z(), -1000);
  EXPECT_EQ(s.cloths[0].materials[0].thicken, 1e6);
}

TEST_F(SceneFiles, JsonNestedMillionsDeepIsRefusedNamingTheLine) {
  // A "motions" value nested 2,000,000 deep parsed, then the scene reader's copy of it recursed
  // once per level and overflowed the stack (a crash, no message).
  const size_t deep = 2000000;
  const std::string nested = std::string(deep, '[') + std::string(deep, ']');
  const std::string path = Write("conf/deep.json", Replace(SceneText(), "\"gravity\"", "\n\"motions\": [" + nested +
                                                                                           "],\n  \"gravity\""));
  ExpectErrorNaming([&] { LoadScene(path); }, {path + ": line 6: ", "nested more than 256 deep"});
}

TEST_F(SceneFiles, AKeyGivenTwiceIsRefusedNamingItsObject) {
  // A strict parser keeps the last of two: the scene ran with frame_steps 1000, unseen.
  const std::string a = Write("conf/a.json", SceneText(", \"frame_steps\": 1000"));
  ExpectErrorNaming([&] { LoadScene(a); }, {a, "\"frame_steps\" is given twice", "top-level object"});
  const std::string b = Write("conf/b.json", SceneText("", "\"mesh\": \"meshes/quad.obj\","));
  ExpectErrorNaming([&] { LoadScene(b); }, {b, "\"mesh\" is given twice", "cloths[0]"});
  // The same key in two objects is not a repeat.
  EXPECT_NO_THROW(LoadScene(Write("conf/c.json", SceneText(", \"wind\": {\"density\": 1}"))));
}

TEST_F(SceneFiles, AFolderNamedAsTheMeshIsRefusedAsAFolder) {
  const std::string a = Write("conf/a.json", Replace(SceneText(), "meshes/quad.obj", (root_ / "meshes").string()));
  ExpectErrorNaming([&] { LoadScene(a); }, {a, "cloths[0].mesh", "is a folder; expected a file"});
  // By a relative name too (found as a folder beside the scene's folder).
  const std::string b = Write("conf/b.json", Replace(SceneText(), "meshes/quad.obj", "meshes"));
  ExpectErrorNaming([&] { LoadScene(b); }, {b, "cloths[0].mesh", "'meshes' is a folder"});
}

TEST_F(SceneFiles, AGustHorizonShorterThanTheSceneWarns) {
  Warnings w;
  const std::string path = Write("conf/gusts.json", Replace(SceneText(", \"wind\": {\"velocity\": [5, 0, 0], "
                                                                       "\"gusts\": {\"rate\": 0.1, \"amplitude\": 2, \"horizon\": 10}}"),
                                                             "\"duration\": 1,", "\"duration\": 20,"));
  const Scene s = LoadScene(path, w.sink());
  EXPECT_TRUE(s.wind.gusts.horizon_given);
  ASSERT_EQ(w.list.size(), 1u);
  EXPECT_NE(w.list[0].find("wind.gusts.horizon"), std::string::npos) << w.list[0];
  EXPECT_NE(w.list[0].find("before the scene's end"), std::string::npos) << w.list[0];
  // Without a horizon: no warning, and none set (Simulate draws them over the run).
  Warnings none;
  const Scene d = LoadScene(Write("conf/gusts2.json", Replace(SceneText(", \"wind\": {\"velocity\": [5, 0, 0], "
                                                                         "\"gusts\": {\"rate\": 0.1, \"amplitude\": 2}}"),
                                                               "\"duration\": 1,", "\"duration\": 20,")),
                            none.sink());
  EXPECT_FALSE(d.wind.gusts.horizon_given);
  EXPECT_TRUE(none.list.empty()) << none.list.front();
}

TEST_F(SceneFiles, StrainLimitsFollowTheSimulatorsRule) {
  // One rule with the simulator's (strain_limiter.h): an upper limit alone ([0, 1.05]) is taken,
  // equal limits ([1, 1], which the simulator refuses) are refused here, naming the key.
  auto with_limits = [&](const std::string& name, const std::string& limits) {
    std::string text = SceneText();
    text.replace(text.find("\"thicken\": 2"), 12, "\"thicken\": 2, \"strain_limits\": " + limits);
    return Write("conf/" + name + ".json", text);
  };
  const Scene upper = LoadScene(with_limits("upper", "[0, 1.05]"));
  EXPECT_EQ(upper.cloths[0].materials[0].strain_min, 0.0);
  EXPECT_EQ(upper.cloths[0].materials[0].strain_max, 1.05);
  const std::string rigid = with_limits("rigid", "[1, 1]");
  ExpectErrorNaming([&] { LoadScene(rigid); }, {rigid, "cloths[0].materials[0].strain_limits", "min < max"});
  const std::string inverted = with_limits("inverted", "[1.05, 0.95]");
  ExpectErrorNaming([&] { LoadScene(inverted); }, {inverted, "strain_limits", "0 <= min <= 1 <= max"});
}

TEST_F(SceneFiles, NaNIsRejectedNamingFileLineAndKey) {
  std::string text = SceneText();
  text.replace(text.find("0.04"), 4, "NaN");
  const std::string path = Write("conf/nan.json", text);
  ExpectErrorNaming([&] { LoadScene(path); }, {path + ":2", "frame_time", "NaN", "numbers must be finite"});
  // The hint only for a number: a syntax error on a line whose string holds "inf" gets none.
  const std::string comma = Write("conf/comma.json", "{\"info\": \"banana\" \"x\": 1 // infinite patience\n}");
  try {
    LoadScene(comma);
    ADD_FAILURE() << "a missing comma was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find("numbers must be finite"), std::string::npos) << e.what();
  }
  // A string ending in an escaped backslash still ends there: the NaN after it gets the hint.
  const std::string escaped = Write("conf/escaped.json", "{\"note\": \"C:\\\\\", \"frame_time\": NaN}");
  ExpectErrorNaming([&] { LoadScene(escaped); }, {"numbers must be finite"});
}

TEST_F(SceneFiles, MissingFilesNameTheKeyAndWhereItLooked) {
  std::string text = SceneText();
  text.replace(text.find("meshes/quad.obj"), 15, "meshes/nope.obj");
  const std::string path = Write("conf/m.json", text);
  ExpectErrorNaming([&] { LoadScene(path); }, {path, "cloths[0].mesh", "nope.obj", "not found"});
  ExpectErrorNaming([&] { LoadScene((root_ / "conf/absent.json").string()); }, {"absent.json"});
}

TEST_F(SceneFiles, HandleOutOfRangeNamesTheHandleAndFile) {
  const std::string path = Write("conf/h.json", SceneText("", "", "[0, 3, 4]"));
  const Scene s = LoadScene(path);
  ExpectErrorNaming([&] { BuildScene(s); }, {path, "handles[0].nodes[2]", "out of range", "4 nodes"});
}

TEST_F(SceneFiles, DegenerateTrianglesAndBadMeshesNameTheMeshKey) {
  Write("meshes/quad.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  const std::string path = Write("conf/deg.json", SceneText());
  const Scene s = LoadScene(path);
  ExpectErrorNaming([&] { BuildScene(s); }, {path, "cloths[0].mesh", "quad.obj"});
  Write("meshes/quad.obj", "v 0 0 0\nv 1 0 nan\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  ExpectErrorNaming([&] { BuildScene(LoadScene(path)); }, {path, "cloths[0].mesh"});
  // A face turned round: named by the OBJ's line, before any refinement.
  Write("meshes/quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 4 3\n");
  ExpectErrorNaming([&] { BuildScene(LoadScene(path)); }, {path, "cloths[0].mesh", "quad.obj:6: face"});
}

TEST_F(SceneFiles, ARestShapeFarFromTheClothsShapeIsRefused) {
  // A 3 m x 2 m cloth whose vt are texture coordinates in 0..1 (as exporters write them), not its
  // rest shape in metres: 6 m^2 over a rest area of 1 m^2, refused naming the ratio.
  Write("meshes/quad.obj",
        "v 0 0 0\nv 3 0 0\nv 3 2 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  const std::string path = Write("conf/uv.json", SceneText());
  ExpectErrorNaming([&] { BuildScene(LoadScene(path)); }, {path, "cloths[0].mesh", "is 6 times its rest area"});
  // The same vt in metres: fine.
  Write("meshes/quad.obj",
        "v 0 0 0\nv 3 0 0\nv 3 2 0\nv 0 2 0\nvt 0 0\nvt 3 0\nvt 3 2\nvt 0 2\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
  EXPECT_NO_THROW(BuildScene(LoadScene(path)));
}

TEST(ResolveScenePath, AbsoluteNextToSceneThenParentThenWorkingDirectory) {
  const fs::path root = fs::temp_directory_path() / ("clothwind_resolve_" + std::to_string(::getpid()));
  fs::create_directories(root / "conf");
  std::ofstream(root / "conf" / "near.obj") << "x";
  std::ofstream(root / "far.obj") << "x";
  const std::string scene = (root / "conf" / "s.json").string();
  EXPECT_EQ(ResolveScenePath(scene, "near.obj"), (root / "conf" / "near.obj").string());
  EXPECT_EQ(ResolveScenePath(scene, "far.obj"), (root / "far.obj").string());
  EXPECT_EQ(ResolveScenePath(scene, (root / "far.obj").string()), (root / "far.obj").string());
  EXPECT_EQ(ResolveScenePath(scene, "missing.obj"), "");
  // A folder is not a file, by absolute path as by relative (it failed later as "no vertices").
  EXPECT_EQ(ResolveScenePath(scene, (root / "conf").string()), "");
  EXPECT_EQ(ResolveScenePath(scene, "conf"), "");
  fs::remove_all(root);
}

}  // namespace
}  // namespace clothwind::sim
