// Where a grid of the cloth's material points lands in each frame of a rendered clip: the
// projected "tracks" a dataset can store beside a clip's frames (DIR/<name>/tracks.json,
// docs/datasets.md), so a network can be trained to read the cloth's motion point by point as
// well as the wind (learn: --aux-tracks), the supervision the window oracle has and a clip's
// single wind label lacks.
#ifndef CLOTHWIND_DATA_CLIP_TRACKS_H_
#define CLOTHWIND_DATA_CLIP_TRACKS_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "data/cloth_animation.h"
#include "render/render_params.h"

namespace clothwind::data {

// A grid of material points: `cols` along the cloth's u (hoist to fly), `rows` along its v.
struct TrackGrid {
  int cols = 8, rows = 6;
  int points() const { return cols * rows; }
};

// "COLSxROWS" (e.g. "8x6") -> the grid. Throws std::invalid_argument naming `option` unless
// both are integers with cols >= 1 and rows >= 2.
TrackGrid ParseTrackGrid(const std::string& option, const std::string& text);

// The vertices nearest a grid of material points, as scripts/window-oracle takes them: column
// a in 0..cols-1 at u = (a + 1) / cols (the hoist column, which does not move, left out; the last
// column is the fly edge), row c in 0..rows-1 at v = c / (rows - 1).
// Inputs: UV  #V by 2 texture coordinates in [0, 1]; grid.
// Output: cols·rows vertex indices, column-major (point a·rows + c).
std::vector<int> GridVertices(const Eigen::MatrixXd& UV, const TrackGrid& grid);

// The projected tracks of a clip.
struct ClipTracks {
  TrackGrid grid;
  int width = 0, height = 0;   // frame size [px]
  std::vector<int> vertices;   // GridVertices, one per point
  // frames x points x 2 continuous image coordinates [px] (x right, y down; pixel (i, j) covers
  // [i, i+1) x [j, j+1), render::PinholeCamera's convention), row-major.
  Eigen::MatrixXf xy;
  // frames x points x 3 positions of the same points in the simulator's frame [m] (FlagSim: x
  // downwind, z up, the hoist on the z axis; the mesh not lifted), row-major: what the cloth did,
  // whatever camera saw it.
  Eigen::MatrixXf world;
  int frames() const { return static_cast<int>(xy.rows()); }
};

// Projects the grid's vertices of frames [0, count) of `animation` (frame k at time k /
// params.fps, as RenderAnimation draws it) through the camera of `params` (render::PlaceCamera,
// the mesh lifted by params.mesh_height), and keeps their positions (ClipTracks::world). Throws std::runtime_error when a point is behind the
// camera (the frames would not show it).
ClipTracks ProjectTracks(const ClothAnimation& animation, const render::RenderParams& params,
                         const TrackGrid& grid, int count);

// tracks.json: {"format": "clothwind-tracks", "version": 1, "grid": [cols, rows], "width",
// "height", "vertices": [...], "xy": [[x0, y0, x1, y1, ...] per frame], "world": [[x0, y0, z0,
// x1, ...] per frame]} with image coordinates to 1/100 px and positions to 1/10 mm ("world" is
// left out when ClipTracks::world is empty; files made before it lack it). (learn/track_targets.h reads it: learn does not link the simulator and renderer.)
nlohmann::json TracksJson(const ClipTracks& tracks);

}  // namespace clothwind::data

#endif  // CLOTHWIND_DATA_CLIP_TRACKS_H_
