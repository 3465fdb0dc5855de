// Test helper: the faces of a square grid of vertices, for tests that fold or crumple a sheet.
#ifndef CLOTHWIND_SIM_TEST_GRID_FACES_H_
#define CLOTHWIND_SIM_TEST_GRID_FACES_H_

#include <Eigen/Core>

namespace clothwind::sim {

// Triangulates an n x n grid of vertices (vertex i * n + j is row i, column j): two triangles per
// cell, (a, a + 1, a + n) and (a + 1, a + n + 1, a + n) for its corner a = i * n + j.
// Inputs: n >= 2 vertices per side. Returns 2 (n - 1)^2 by 3 vertex indices.
inline Eigen::MatrixX3i GridFaces(int n) {
  Eigen::MatrixX3i F(2 * (n - 1) * (n - 1), 3);
  int k = 0;
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j + 1 < n; ++j) {
      const int a = i * n + j;
      F.row(k++) << a, a + 1, a + n;
      F.row(k++) << a + 1, a + n + 1, a + n;
    }
  return F;
}

}  // namespace clothwind::sim

#endif  // CLOTHWIND_SIM_TEST_GRID_FACES_H_
