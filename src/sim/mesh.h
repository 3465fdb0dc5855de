#ifndef CLOTHWIND_SIM_MESH_H_
#define CLOTHWIND_SIM_MESH_H_

#include <string>
#include <vector>

#include <Eigen/Core>

namespace clothwind::sim {

// A triangle cloth mesh with one material-space (rest) coordinate per vertex.
//
// ArcSim keeps the rest shape in material space: from the OBJ's `vt` lines when present, else
// from the x,y of the positions as read (before the scene transform is applied). We do the same,
// one material coordinate per vertex (no texture seams).
struct Mesh {
  Eigen::MatrixX3d V;  // #V by 3 world positions [m]
  Eigen::MatrixX3i F;  // #F by 3 vertex indices (0-based), counter-clockwise in material space
  Eigen::MatrixX2d U;  // #V by 2 material-space rest coordinates [m]
};

// Reads a Wavefront OBJ: `v x y z`, optional `vt u v`, `f a b c ...` (also a/t, a/t/n, a//n;
// polygons are fan-triangulated; negative (relative) indices are accepted). Without `vt`, U is
// the x,y of the positions (ArcSim's rule). The result is validated (ValidateMesh). Lines may end
// in LF, CRLF or a lone CR, and a UTF-8 byte order mark at the start is skipped. Other standard
// OBJ keywords (vn, o, g, s, usemtl, mtllib, l, ...) and ArcSim's annotations (vl, nv, ny, e, tm,
// ...) are skipped; any other keyword (e.g. 'F', 'V': OBJ is case-sensitive) is an error naming
// its line, rather than a face or vertex silently lost.
// Inputs:
//   path  file to read
// Returns the mesh. Throws std::runtime_error naming path:line and what was expected on bad input.
// topology: also check what the simulator needs of a cloth (ValidateMesh's topology checks);
// false for meshes that are only drawn (an OBJ frame sequence to render: exporters leave loose
// vertices and mixed winding, which a renderer does not mind).
Mesh ReadObj(const std::string& path, bool topology = true);

// Writes `v` (positions), `vt` (material coordinates) and `f a/a b/b c/c` lines, atomically
// (temporary file then rename), with full double precision so ReadObj(WriteObj(m)) == m.
// Inputs:
//   path  destination
//   mesh  mesh to write (U may be empty: then no vt lines)
// Throws std::runtime_error when the file cannot be written.
void WriteObj(const std::string& path, const Mesh& mesh);

// Checks: V, F, U shapes agree; no NaN/inf; indices in range; no repeated index in a face; no
// degenerate triangle (world and material area > 1e-12 m^2 relative to the squared edge scale);
// every vertex in a face; every edge used at most once in each direction (faces consistently
// oriented, no edge of more than two faces).
// Inputs:
//   mesh       mesh to check
//   what       name used in the error message (e.g. the file name)
//   obj_lines  optional, one per face: the OBJ line it came from; then errors give the line and
//              number vertices from 1, as the file does ("flag.obj:59: face runs from vertex 8
//              to vertex 4 as the face on line 60 does: ...")
// Throws std::invalid_argument naming `what`, the offending vertex/face and the problem.
//   topology   false: skip the last two checks (a mesh only drawn, not simulated)
void ValidateMesh(const Mesh& mesh, const std::string& what = "mesh", const std::vector<int>& obj_lines = {},
                  bool topology = true);

// Uniform 1-to-4 midpoint subdivision, repeated until every edge (in world space and in material
// space) is at most max_edge. New vertices are edge midpoints in both V and U, so area, boundary
// and the (planar) rest shape are preserved exactly; the original vertices keep their indices
// (handles stay valid), new ones follow.
// Inputs:
//   mesh      mesh to refine (valid)
//   max_edge  longest allowed edge [m], > 0
// Returns the refined mesh.
Mesh RefineMesh(const Mesh& mesh, double max_edge);

// Splits only the edges longer than max_edge (in world or material space) at their midpoints,
// red-green style so the mesh stays conforming: a face with one long edge becomes 2 triangles,
// with two long edges 3 (the remaining quad cut along its shorter material-space diagonal), with
// three 4; repeated until every edge is at most max_edge. Unlike RefineMesh it leaves short edges
// alone, so it reaches a given longest edge with fewer vertices on an irregular mesh (ArcSim's
// flag: RefineMesh to 0.5 m, then this to 0.2 m gives 485 vertices with every edge <= 0.2 m,
// where RefineMesh to 0.25 m gives 811), at the price of less regular triangles. Area, boundary
// and rest shape are preserved exactly, original vertices keep their indices, new ones follow.
// Inputs:
//   mesh      mesh to refine (valid)
//   max_edge  longest allowed edge [m], > 0
// Returns the refined mesh. Throws std::invalid_argument for max_edge <= 0, or when 12 passes
// do not reach max_edge.
Mesh SplitLongEdges(const Mesh& mesh, double max_edge);

// Longest edge of the mesh in world space [m] (0 for an empty mesh).
double MaxEdgeLength(const Mesh& mesh);

// Sum of triangle areas in world space [m^2].
double SurfaceArea(const Mesh& mesh);

// Sum of triangle areas in material space [m^2].
double RestArea(const Mesh& mesh);

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_MESH_H_
