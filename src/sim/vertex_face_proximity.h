#ifndef CLOTHWIND_SIM_VERTEX_FACE_PROXIMITY_H_
#define CLOTHWIND_SIM_VERTEX_FACE_PROXIMITY_H_

#include <cstdint>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace clothwind::sim {

// Finds vertex-face pairs of one mesh closer than a thickness (a vertex whose projection onto a
// non-incident face's plane lies inside the face, within the thickness of it), with a spatial
// hash grid of the vertices; the repulsion forces of the simulator act on these pairs. Results
// are deterministic (ordered by face, then vertex). Buffers are reused between calls.
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
  //   cell_size     hash grid cell [m] (> 0), e.g. the mean edge length but at least an eighth
  //                 of the longest (see Update); raised to 2 thickness
  VertexFaceProximity(const Eigen::MatrixX3i& F, int num_vertices, double cell_size);

  // Recomputes the pairs for positions X (#V by 3) [m] and thickness [m] (> 0). Stays bounded
  // (about 33^3 cells per face at most) on any input: non-finite or astronomically far vertices
  // are left out, and faces whose bounding box is non-finite or spans more than 32 cells along an
  // axis are skipped (an exploded state, never a cloth's face when the cell is at least an eighth
  // of the longest rest edge, as the simulator sizes it).
  void Update(const Eigen::MatrixX3d& X, double thickness);

  // The same pairs as Update (same order), looked for only among `candidates` (vertex, face)
  // pairs, each listed at most once, that must include every pair within thickness (e.g. the
  // crossing resolver's vertex-face candidates of the step that ended at X, with a broad-phase
  // reach >= thickness). Saves Update's grid when such a list is at hand.
  void UpdateFromCandidates(const Eigen::MatrixX3d& X, double thickness,
                            const std::vector<std::pair<int, int>>& candidates);

  // Pairs found by the last Update.
  const std::vector<Pair>& pairs() const { return pairs_; }

 private:
  Eigen::MatrixX3i F_;
  int num_vertices_;
  double cell_size_;
  std::vector<int> bucket_head_;   // per hash bucket: first vertex, -1 if none
  std::vector<int> next_;          // per vertex: next vertex in the same bucket
  std::vector<std::uint64_t> key_; // per vertex: its cell key
  std::vector<Pair> pairs_;
  std::vector<int> found_;         // scratch: vertices found for one face
  std::vector<Pair> scratch_;      // scratch: UpdateFromCandidates' pairs before sorting
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_VERTEX_FACE_PROXIMITY_H_
