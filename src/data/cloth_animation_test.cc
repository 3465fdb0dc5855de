#include "data/cloth_animation.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include <gtest/gtest.h>

#include "data/paths.h"
#include "sim/mesh.h"
#include "sim/scene.h"
#include "sim/scene_builder.h"
#include "sim/simulate.h"

namespace clothwind::data {
namespace {

namespace fs = std::filesystem;

sim::Trajectory ShortFlag() {
  sim::BuildOptions b;
  b.max_edge = 1.0;
  const sim::SceneSetup setup = sim::BuildScene(sim::LoadScene(DefaultScenePath(render::SceneKind::kFlag)), b);
  sim::Theta theta = sim::SceneTheta(setup);
  theta[sim::kWindSpeedIndex] = 6.0;
  sim::SimulateOptions o;
  o.duration = 0.2;
  return sim::SimulateTrajectory(setup, theta, o);
}

// Writes frames as ArcSim does (NNNN_00.obj with vt = material coordinates).
fs::path WriteObjs(const sim::Trajectory& t, const std::string& tag) {
  const fs::path dir = fs::temp_directory_path() / ("clothwind_anim_" + tag + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (int f = 0; f < t.num_frames(); ++f) {
    sim::Mesh m;
    m.F = t.faces;
    m.U = t.uv.cast<double>();
    m.V = t.frames[f].cast<double>();
    char name[32];
    std::snprintf(name, sizeof(name), "%04d_00.obj", f);
    sim::WriteObj((dir / name).string(), m);
  }
  return dir;
}

TEST(ClothAnimationTest, TextureCoordinatesSpanTheUnitSquareHoistToFly) {
  const sim::Trajectory t = ShortFlag();
  const ClothAnimation a = AnimationFromTrajectory(t);
  ASSERT_EQ(a.UV.rows(), t.num_vertices());
  EXPECT_DOUBLE_EQ(a.UV.col(0).minCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(a.UV.col(0).maxCoeff(), 1.0);
  EXPECT_DOUBLE_EQ(a.UV.col(1).minCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(a.UV.col(1).maxCoeff(), 1.0);
  // At rest the hoist (u = 0) is on the z axis, the fly end (u = 1) 3 m away along y.
  for (int v = 0; v < t.num_vertices(); ++v) {
    EXPECT_NEAR(t.frames[0](v, 1), 3.0 * a.UV(v, 0), 1e-5);
    EXPECT_NEAR(t.frames[0](v, 2), 2.0 * a.UV(v, 1), 1e-5);
  }
}

TEST(ClothAnimationTest, AVertexNoFaceUsesDoesNotSizeTheCloth) {
  // A 1 m square of two faces and a stray vertex at u = 5 (an OBJ from a modelling tool): the
  // cloth measured 5 m across, rendered small and framed for the larger one.
  const fs::path dir = fs::temp_directory_path() / ("clothwind_anim_stray" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  sim::Mesh m;
  m.V.resize(5, 3);
  m.V << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 5, 0, 0;
  m.U = m.V.leftCols(2);
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  sim::WriteObj((dir / "0000_00.obj").string(), m);
  const ClothAnimation a = ReadObjSequence(dir.string(), 0, 0.04);
  EXPECT_DOUBLE_EQ(a.rest_size.x(), 1.0);
  EXPECT_DOUBLE_EQ(a.rest_size.y(), 1.0);
  EXPECT_DOUBLE_EQ(a.UV(2, 0), 1.0);  // the square's far corner spans the texture
  fs::remove_all(dir);
}

TEST(ClothAnimationTest, ObjFramesRenderExactlyLikeTheTrajectory) {
  const sim::Trajectory t = ShortFlag();
  const fs::path dir = WriteObjs(t, "same");
  const ClothAnimation from_traj = AnimationFromTrajectory(t);
  const ClothAnimation from_obj = ReadObjSequence(dir.string(), 0, t.frame_time);
  ASSERT_EQ(from_obj.num_frames(), t.num_frames());
  render::RenderParams p = render::SampleRenderParams(render::SceneKind::kFlag, 3);
  p.width = p.height = 48;
  p.samples = 1;
  render::RenderOptions ro;
  ro.threads = 1;
  render::Renderer r1(p, ro), r2(p, ro);
  const auto a = RenderAnimation(&r1, from_traj, 0.04, 3, 25.0);
  const auto b = RenderAnimation(&r2, from_obj, 0.04, 3, 25.0);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(cv::norm(a[k], b[k], cv::NORM_INF), 0.0) << k;
  // And the flag moves between frames.
  EXPECT_GT(cv::norm(a[0], a[2], cv::NORM_L1), 0.0);
  fs::remove_all(dir);
}

TEST(ClothAnimationTest, FrameAtInterpolatesAndHandlesRemeshing) {
  const sim::Trajectory t = ShortFlag();
  ClothAnimation a = AnimationFromTrajectory(t);
  const ClothFrame mid = FrameAt(a, 0.5 * t.frame_time * 3);  // between frames 1 and 2
  const Eigen::MatrixXd expect = 0.5 * (t.frames[1].cast<double>() + t.frames[2].cast<double>());
  EXPECT_LT((mid.V - expect).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(mid.F, a.F);
  // A quarter of the way: three quarters of the earlier frame (at the midpoint, weights swapped
  // between the two frames gave the same blend).
  const ClothFrame quarter = FrameAt(a, 1.25 * t.frame_time);
  const Eigen::MatrixXd expect_quarter = 0.75 * t.frames[1].cast<double>() + 0.25 * t.frames[2].cast<double>();
  EXPECT_LT((quarter.V - expect_quarter).cwiseAbs().maxCoeff(), 1e-9);
  // Clamped outside the animation.
  EXPECT_EQ(FrameAt(a, -1.0).V, a.frames[0].V);
  EXPECT_EQ(FrameAt(a, 99.0).V, a.frames.back().V);
  // A frame with its own topology (ArcSim remeshed) is never blended: the nearer one is used.
  ClothFrame remeshed;
  remeshed.V = Eigen::MatrixXd::Zero(3, 3);
  remeshed.V.row(1) << 1, 0, 0;
  remeshed.V.row(2) << 0, 0, 1;
  remeshed.F = (Eigen::MatrixXi(1, 3) << 0, 1, 2).finished();
  remeshed.UV = Eigen::MatrixXd::Zero(3, 2);
  a.frames[2] = remeshed;
  EXPECT_EQ(FrameAt(a, 1.4 * t.frame_time).V, a.frames[1].V);
  EXPECT_EQ(FrameAt(a, 1.6 * t.frame_time).F, remeshed.F);
}

TEST(ClothAnimationTest, MissingObjSequenceIsReportedByName) {
  try {
    ReadObjSequence("/nonexistent-folder", 2);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0000_02.obj"), std::string::npos) << e.what();
  }
  EXPECT_THROW(AnimationFromTrajectory(ShortFlag(), 3, 100), std::out_of_range);
}

TEST(ClothAnimationTest, AFrameMissingInTheMiddleIsReportedByName) {
  // The sequence used to end at the hole, the later frames dropped without a word.
  const sim::Trajectory t = ShortFlag();
  const fs::path dir = WriteObjs(t, "hole");
  ASSERT_GE(t.num_frames(), 3);
  fs::remove(dir / "0001_00.obj");
  try {
    ReadObjSequence(dir.string(), 0, t.frame_time);
    ADD_FAILURE() << "a sequence with a hole was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("0001_00.obj is missing"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace clothwind::data
