#ifndef CLOTHWIND_SIM_VERTEX_FACE_PROXIMITY_H_
#define CLOTHWIND_SIM_VERTEX_FACE_PROXIMITY_H_

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace clothwind::sim {

// Finds vertex-face pairs of one mesh closer than a thickness (a vertex whose projection onto a
// non-incident face's plane lies inside the face, within the thickness of it), with a spatial
// hash of the vertices; the repulsion forces of the simulator act on these pairs. Results are
// deterministic (sorted). Buffers are reused between calls.
class VertexFaceProximity {
 public:
  struct Pair {
    int vertex;
    int face;
    double side;  // +1: vertex on the side the face normal points to, -1: the other side
  };

  // Inputs:
  //   F             #F by 3 faces (indices < num_vertices)
  //   num_vertices  #V
  VertexFaceProximity(const Eigen::MatrixX3i& F, int num_vertices);

  // Recomputes the pairs for positions X (#V by 3) [m] and thickness [m] (> 0).
  void Update(const Eigen::MatrixX3d& X, double thickness);

  // Pairs found by the last Update, ordered by (face, vertex).
  const std::vector<Pair>& pairs() const { return pairs_; }

 private:
  Eigen::MatrixX3i F_;
  int num_vertices_;
  std::vector<std::pair<std::uint64_t, int>> cells_;  // (cell key, vertex), sorted
  std::vector<Pair> pairs_;
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_VERTEX_FACE_PROXIMITY_H_
