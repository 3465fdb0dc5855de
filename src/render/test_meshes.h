#ifndef CLOTHWIND_RENDER_TEST_MESHES_H_
#define CLOTHWIND_RENDER_TEST_MESHES_H_

#include <Eigen/Core>

namespace clothwind::render {

// A cloth mesh as the renderer takes it.
struct ClothMesh {
  Eigen::MatrixXd V;   // #V by 3 positions [m]
  Eigen::MatrixXi F;   // #F by 3 faces
  Eigen::MatrixXd UV;  // #V by 2 texture coordinates
};

// A flag waving in a travelling wave, for benches, tests and demos (not physics): a regular
// grid of nx by ny vertices over width by height metres in the simulator's frame (hoist on the
// z axis from z = 0 to z = height, flying along +x), displaced sideways (y) by a wave whose
// amplitude grows towards the fly end, and drooping a little.
// Inputs: nx, ny  vertices along the length and height (>= 2); width, height [m];
//   time [s]  phase of the wave; amplitude [m] at the fly end; frequency [Hz].
ClothMesh WavingFlag(int nx = 39, int ny = 26, double width = 3.0, double height = 2.0,
                     double time = 0.0, double amplitude = 0.3, double frequency = 1.5);

// A cloth hanging from its top edge (y from 0 to width at z = height, in the plane x = 0)
// and billowing along +x in a wave, for benches and demos of the ClothSim scene.
// Inputs: nx, ny  vertices across and down (>= 2); width, height [m]; time [s];
//   amplitude [m] of the billow at the bottom edge; frequency [Hz].
ClothMesh HangingCloth(int nx = 32, int ny = 32, double width = 1.0, double height = 1.0,
                       double time = 0.0, double amplitude = 0.12, double frequency = 0.8);

// A flat rectangle in the plane x = 0 (y from 0 to width, z from 0 to height), for tests.
// Inputs: nx, ny  vertices along y and z (>= 2).
ClothMesh FlatCloth(int nx, int ny, double width, double height);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_TEST_MESHES_H_
