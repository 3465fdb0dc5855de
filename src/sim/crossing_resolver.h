#ifndef CLOTHWIND_SIM_CROSSING_RESOLVER_H_
#define CLOTHWIND_SIM_CROSSING_RESOLVER_H_

#include <array>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace clothwind::sim {

// Undoes the crossings of one time step (a cheap stand-in for ArcSim's continuous collision
// handling and impact zones). The repulsion (vertex_face_proximity.h) only sees pairs that start
// a step within its thickness; a fold moving faster than thickness / dt jumps through between
// two detections, and once through, the repulsion pushes further along the side it is now on.
// After the step, this finds
//  - every vertex that changed side of a non-incident face while its path crossed the face
//    (linear motion of all four points over the step, the crossing point tested against the
//    face at that moment), and
//  - every pair of edges (no shared vertex) that passed through each other (the sign of their
//    tetrahedron's volume changed, and at that moment the lines met within both edges),
// and moves the pair back to its original side, `gap` apart along the end normal, removing the
// approaching normal velocity (inelastic); both are shared among the four points by inverse
// mass, so momentum and the centre of mass are kept. Sweeps repeat until nothing is left to
// correct or `max_sweeps`. Candidates: the primitives of faces that share a vertex (fixed lists)
// and of faces whose swept boxes meet in a sort and sweep, tested box against box.
// Deterministic. Buffers are reused.
class CrossingResolver {
 public:
  // Inputs:
  //   F             #F by 3 faces (indices < num_vertices)
  //   inverse_mass  #V inverse node masses [1/kg] (0 = pinned)
  CrossingResolver(const Eigen::MatrixX3i& F, const Eigen::VectorXd& inverse_mass);

  // Inputs:
  //   X0   #V by 3 positions at the start of the step [m]
  //   gap  distance from the face the corrected vertex is put at [m] (>= 0)
  //   max_sweeps  passes over the candidates (>= 1)
  // Input/Outputs:
  //   X    #V by 3 positions at the end of the step [m], corrected
  //   V    #V by 3 velocities [m/s], approaching normal velocity of corrected pairs removed
  // Returns the number of corrections made (a pair corrected in two sweeps counts twice).
  // reach: broad-phase distance (>= gap; less is raised to gap): pairs whose swept boxes come
  // within it are tested. With reach >= a thickness h, vertex_face_candidates() holds every
  // (non-incident) vertex-face pair within h at the end positions, so long as nothing was corrected.
  int Resolve(const Eigen::MatrixX3d& X0, double gap, double reach, int max_sweeps, Eigen::MatrixX3d* X,
              Eigen::MatrixX3d* V);

  // (vertex, face) pairs whose swept boxes came within reach in the last Resolve (each once).
  const std::vector<std::pair<int, int>>& vertex_face_candidates() const { return candidates_; }
  // Pairs of edges (indices into edges(), no shared vertex) whose swept boxes came within reach
  // in the last Resolve (each once, lower index first).
  const std::vector<std::pair<int, int>>& edge_edge_candidates() const { return edge_candidates_; }
  // The mesh's unique edges (a < b), sorted.
  const std::vector<std::pair<int, int>>& edges() const { return edges_; }

  // Boxes are compared in single precision, each grown by this much [m] beyond the reach, so
  // rounding never loses a pair (coordinates within +-100 m: float spacing <= 7.6e-6 m there).
  static constexpr double kBoxPadding = 1e-5;

 private:
  // A swept box in single precision: lo[0..2], hi[0..2] (lane 3 unused, 0), for SSE tests.
  struct alignas(16) Box {
    float lo[4];
    float hi[4];
  };

  // Vertex-face pairs (vertex not of the face) into candidates_ and edge-edge pairs (no shared
  // vertex) into edge_candidates_ whose swept boxes (start and end positions) overlap within reach.
  void FindCandidates(const Eigen::MatrixX3d& X0, const Eigen::MatrixX3d& X1, double reach);
  // Calls vertex_face(v, f) for each vertex v owned by p or q and the other face f, v not of f,
  // and edge_edge(i, j) (i < j) for each pair of edges owned by p and q with no shared vertex.
  template <class VertexFace, class EdgeEdge>
  void ForEachOwnedPair(int p, int q, VertexFace vertex_face, EdgeEdge edge_edge) const;
  // Appends the pairs of owned primitives of faces p and q whose boxes overlap within reach.
  void ExpandFacePair(int p, int q, float reach);
  // One pass over the candidates; returns the corrections made.
  int SweepVertexFace(const Eigen::MatrixX3d& X0, double gap, Eigen::MatrixX3d* X, Eigen::MatrixX3d* V);
  int SweepEdgeEdge(const Eigen::MatrixX3d& X0, double gap, Eigen::MatrixX3d* X, Eigen::MatrixX3d* V);
  // Moves points id[k] by inverse mass along n so that sum_k coef[k] n.x[id[k]] >= gap, and
  // removes the approaching part of sum_k coef[k] n.v[id[k]]. False when nothing could move.
  bool Push(const int id[4], const double coef[4], const Eigen::Vector3d& n, double gap, Eigen::MatrixX3d* X,
            Eigen::MatrixX3d* V) const;

  // Pairs (p < q) of face_boxes_ that overlap when grown by reach and share no vertex, into
  // overlaps_ (sort and sweep), in sweep order.
  void OverlappingFarPairs(float reach);
  bool ShareVertex(int p, int q) const;

  std::vector<std::array<int, 3>> faces_;             // the faces' vertex indices
  Eigen::VectorXd inverse_mass_;
  std::vector<std::pair<int, int>> edges_;            // unique edges (a < b)
  std::vector<std::pair<int, int>> candidates_;       // vertex-face pairs (vertex, face)
  std::vector<std::pair<int, int>> edge_candidates_;  // edge index pairs, no shared vertex
  // Each vertex and edge is owned by one face holding it: per face f, its vertices are
  // owned_vertices_[owned_start_[f] .. owned_start_[f + 1]), its edges (indices into edges_) likewise.
  std::vector<int> owned_start_, owned_vertices_, owned_edge_start_, owned_edges_;
  // The owned-primitive pairs of every two faces that share a vertex (neighbours in the sheet,
  // whose boxes always touch), fixed with the mesh: box-tested each step instead of being found
  // by the sweep (they are ~90 % of the overlapping face pairs).
  std::vector<std::pair<int, int>> near_vertex_face_;  // (vertex, face)
  std::vector<std::pair<int, int>> near_edge_edge_;    // (edge, edge), lower index first
  std::vector<Box> vertex_boxes_, edge_boxes_, face_boxes_;  // scratch: swept boxes
  // Sort and sweep (OverlappingFarPairs): the faces in order of their low end along the sweep
  // axis (kept between steps), and their boxes in that order, one array per bound.
  std::vector<int> sweep_order_;
  std::vector<float> sweep_a_lo_, sweep_a_hi_, sweep_b_lo_, sweep_b_hi_, sweep_c_lo_, sweep_c_hi_;
  std::vector<std::pair<int, int>> overlaps_;         // scratch: overlapping far face pairs
};

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_CROSSING_RESOLVER_H_
