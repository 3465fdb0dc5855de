#include "data/clip_tracks.h"

#include <cmath>
#include <stdexcept>

#include "common/parse_pair.h"
#include "render/camera.h"

namespace clothwind::data {

TrackGrid ParseTrackGrid(const std::string& option, const std::string& text) {
  TrackGrid g;
  const auto stoi = [](const std::string& t, size_t* n) { return std::stoi(t, n); };
  // At most 256 a side: 3000x3000 points ran for minutes on a 63-vertex mesh.
  if (!ParsePair(text, 'x', stoi, &g.cols, &g.rows) || g.cols < 1 || g.rows < 2 || g.cols > 256 || g.rows > 256)
    throw std::invalid_argument(option + ": expected COLSxROWS with 1 <= COLS <= 256 and 2 <= ROWS <= 256 (e.g. 8x6), "
                                "got '" + text + "'");
  return g;
}

std::vector<int> GridVertices(const Eigen::MatrixXd& UV, const TrackGrid& grid) {
  if (UV.rows() == 0 || UV.cols() != 2) throw std::invalid_argument("GridVertices: UV must be #V by 2, #V > 0");
  std::vector<int> vertices;
  for (int a = 0; a < grid.cols; ++a) {
    for (int c = 0; c < grid.rows; ++c) {
      const Eigen::RowVector2d target((a + 1.0) / grid.cols, static_cast<double>(c) / (grid.rows - 1));
      Eigen::Index nearest = 0;
      (UV.rowwise() - target).rowwise().squaredNorm().minCoeff(&nearest);
      vertices.push_back(static_cast<int>(nearest));
    }
  }
  return vertices;
}

ClipTracks ProjectTracks(const ClothAnimation& animation, const render::RenderParams& params,
                         const TrackGrid& grid, int count) {
  if (count < 1 || animation.num_frames() < 1)
    throw std::invalid_argument("ProjectTracks: expected count >= 1 frames of a non-empty animation");
  ClipTracks t;
  t.grid = grid;
  t.width = params.width;
  t.height = params.height;
  t.vertices = GridVertices(animation.UV, grid);
  const render::PinholeCamera camera = render::PlaceCamera(params);
  const Eigen::Vector3d lift(0, 0, params.mesh_height);
  t.xy.resize(count, 2 * grid.points());
  t.world.resize(count, 3 * grid.points());
  for (int k = 0; k < count; ++k) {
    const ClothFrame frame = FrameAt(animation, k / params.fps);
    for (int p = 0; p < grid.points(); ++p) {
      Eigen::Vector2d pixel;
      if (!camera.Project(frame.V.row(t.vertices[p]).transpose() + lift, &pixel))
        throw std::runtime_error("ProjectTracks: point " + std::to_string(p) + " (vertex " +
                                 std::to_string(t.vertices[p]) + ") is behind the camera in frame " +
                                 std::to_string(k));
      t.xy(k, 2 * p) = static_cast<float>(pixel.x());
      t.xy(k, 2 * p + 1) = static_cast<float>(pixel.y());
      for (int c = 0; c < 3; ++c) t.world(k, 3 * p + c) = static_cast<float>(frame.V(t.vertices[p], c));
    }
  }
  return t;
}

nlohmann::json TracksJson(const ClipTracks& t) {
  nlohmann::json xy = nlohmann::json::array();
  for (int k = 0; k < t.frames(); ++k) {
    nlohmann::json row = nlohmann::json::array();
    // 1/100 px: far below what a frame resolves, and a third of the file of full floats.
    for (int i = 0; i < t.xy.cols(); ++i) row.push_back(std::round(t.xy(k, i) * 100.0) / 100.0);
    xy.push_back(std::move(row));
  }
  nlohmann::json j = {{"format", "clothwind-tracks"}, {"version", 1},       {"grid", {t.grid.cols, t.grid.rows}},
                      {"width", t.width},             {"height", t.height}, {"vertices", t.vertices},
                      {"xy", std::move(xy)}};
  if (t.world.size() > 0) {
    nlohmann::json world = nlohmann::json::array();
    for (int k = 0; k < t.world.rows(); ++k) {
      nlohmann::json row = nlohmann::json::array();
      // 1/10 mm: a 128-px frame of a 3 m flag 4-6 m away shows ~20 mm a pixel.
      for (int i = 0; i < t.world.cols(); ++i) row.push_back(std::round(t.world(k, i) * 1e4) / 1e4);
      world.push_back(std::move(row));
    }
    j["world"] = std::move(world);
  }
  return j;
}

}  // namespace clothwind::data
