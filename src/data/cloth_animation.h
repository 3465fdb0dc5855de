#ifndef CLOTHWIND_DATA_CLOTH_ANIMATION_H_
#define CLOTHWIND_DATA_CLOTH_ANIMATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "render/renderer.h"
#include "sim/trajectory_io.h"

namespace clothwind::data {

// One frame of a cloth animation as the renderer takes it.
struct ClothFrame {
  Eigen::MatrixXd V;   // #V by 3 positions [m], simulator frame (z up, hoist on the z axis)
  Eigen::MatrixXi F;   // #F by 3 faces; empty: the animation's shared faces
  Eigen::MatrixXd UV;  // #V by 2 texture coordinates in [0,1]; empty: the shared ones
};

// A cloth animation from any simulator: our trajectories (fixed topology) or a sequence of OBJ
// frames such as ArcSim's (whose remeshing may change the topology from frame to frame). The
// renderer draws both the same way, so other simulators' cloth renders identically.
struct ClothAnimation {
  double frame_time = 0.04;       // time between frames [s]
  Eigen::MatrixXi F;              // shared faces (frames with empty F use these)
  Eigen::MatrixXd UV;             // shared texture coordinates in [0,1]
  std::vector<ClothFrame> frames;
  // The cloth's size at rest [m]: the extent of its material space (u, v), the bounds the
  // texture coordinates were normalised with. Zero when unknown (an animation built by hand).
  Eigen::Vector2d rest_size = Eigen::Vector2d::Zero();

  int num_frames() const { return static_cast<int>(frames.size()); }
  double duration() const { return frames.empty() ? 0.0 : (frames.size() - 1) * frame_time; }
};

// Texture coordinates in [0,1] from material-space rest coordinates [m]: each column mapped
// from [lo, hi] to [0, 1], with lo/hi the bounds of the cloth's material space (u from hoist to
// fly, v from bottom to top for the flag meshes, whose material x runs along the fly).
// Inputs: U  #V by 2 material coordinates [m]; lo, hi  2-vectors, hi > lo.
// Returns #V by 2.
Eigen::MatrixXd NormalizeTextureCoordinates(const Eigen::MatrixXd& U, const Eigen::Vector2d& lo,
                                            const Eigen::Vector2d& hi);

// The frames [first, first + count) of a trajectory (count < 0: to the end).
// Throws std::out_of_range when the range is outside the trajectory.
ClothAnimation AnimationFromTrajectory(const sim::Trajectory& t, int first = 0, int count = -1);

// Reads ArcSim-style frame OBJs "<folder>/NNNN_CC.obj" (frame NNNN, cloth CC), frames 0, 1, ...
// until the first missing number. Texture coordinates come from each OBJ's material coordinates
// (`vt`, or x,y when absent, ArcSim's rule), normalised with the bounds of the first frame.
// Inputs: folder; cloth index; frame_time [s] of the sequence (ArcSim's scene frame_time).
// Throws std::runtime_error naming the folder when no frame exists, or a file's error.
ClothAnimation ReadObjSequence(const std::string& folder, int cloth = 0, double frame_time = 0.04);

// The cloth at time t [s] (frame 0 at t = 0): linear interpolation between the two nearest
// frames when they share the topology, else the nearer frame. t is clamped to the animation.
// The returned frame has F and UV filled in.
ClothFrame FrameAt(const ClothAnimation& a, double t);

// Renders frames at `fps` starting at time `start` [s]: frame k shows FrameAt(start + k / fps).
// Inputs: renderer (its ζ sets camera, light, texture, size); a; start [s]; count >= 1; fps > 0.
// Returns count CV_8UC3 BGR images.
std::vector<cv::Mat> RenderAnimation(render::Renderer* renderer, const ClothAnimation& a,
                                     double start, int count, double fps);

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_CLOTH_ANIMATION_H_
