#ifndef CLOTHWIND_SIM_TRAJECTORY_IO_H_
#define CLOTHWIND_SIM_TRAJECTORY_IO_H_

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace clothwind::sim {

using FramePositions = Eigen::Matrix<float, Eigen::Dynamic, 3, Eigen::RowMajor>;

// A simulated cloth: fixed connectivity, one set of vertex positions per frame.
struct Trajectory {
  Eigen::MatrixX3i faces;                 // #F by 3 vertex indices
  Eigen::MatrixX2f uv;                    // #V by 2 material-space rest coordinates [m] (texturing)
  double frame_time = 0.04;               // time between frames [s]
  std::vector<FramePositions> frames;     // #frames, each #V by 3 world positions [m]; frame 0 = start

  // Run statistics (not stored in the binary file).
  int64_t steps = 0;                      // time steps taken
  double wall_seconds = 0.0;              // wall time of the simulation [s]
  int64_t solver_iterations = 0;          // linear-solver (CG) iterations summed over the steps
  int64_t strain_limit_sweeps = 0;        // the strain limiter's sweeps summed over the steps
  int64_t strain_limit_unconverged = 0;   // steps whose limiter stopped outside its tolerance

  int num_vertices() const { return static_cast<int>(uv.rows()); }
  int num_faces() const { return static_cast<int>(faces.rows()); }
  int num_frames() const { return static_cast<int>(frames.size()); }
};

// The binary trajectory format (.cwtraj), version 1, all little-endian:
//   offset  size            field
//   0       8               magic "CWTRAJ\0\0"
//   8       4   uint32      version (1)
//   12      4   uint32      #V vertices
//   16      4   uint32      #F faces
//   20      4   uint32      #frames
//   24      8   float64     frame_time [s]
//   32      12 #F  int32    faces, 3 vertex indices each (0-based)
//   ...     8 #V   float32  uv: material rest coordinates [m], 2 per vertex
//   ...     12 #V #frames float32  positions [m], frame after frame, x y z per vertex
// The file size is therefore 32 + 12 #F + 8 #V + 12 #V #frames bytes.
constexpr char kTrajectoryMagic[8] = {'C', 'W', 'T', 'R', 'A', 'J', '\0', '\0'};
constexpr uint32_t kTrajectoryVersion = 1;

// Writes a trajectory atomically (temporary file in the same folder, then rename).
// Throws std::runtime_error naming the file if it cannot be written, or std::invalid_argument if
// the frames' shapes disagree with uv.
void WriteTrajectory(const std::string& path, const Trajectory& trajectory);

// Reads a trajectory; throws std::runtime_error naming the file and what is wrong (bad magic,
// version, truncated, face index out of range, non-finite positions).
Trajectory ReadTrajectory(const std::string& path);

// Writes `bytes` to `path` atomically (temporary name in the same folder, then rename).
void WriteFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_TRAJECTORY_IO_H_
