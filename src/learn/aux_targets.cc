#include "learn/aux_targets.h"

#include <filesystem>
#include <stdexcept>
#include <string>

namespace clothwind::learn {
namespace fs = std::filesystem;

std::vector<float> AuxTargetsOf(const Tracks& tracks, int first, int frames, const cv::Rect& crop, int source_side,
                                bool flipped, int phase_bins, bool world) {
  std::vector<float> y = TrackTargets(tracks, first, frames, crop, source_side, flipped, phase_bins);
  if (world) {
    const std::vector<float> w = WorldTrackTargets(tracks, first, frames, flipped);
    y.insert(y.end(), w.begin(), w.end());
  }
  return y;
}

AuxTargets ReadAuxTargets(const std::vector<ClipInfo>& clips, const SampleOptions& options, int phase_bins,
                          bool world) {
  AuxTargets aux;
  aux.phase_bins = phase_bins;
  aux.world = world;
  aux.tracks.resize(clips.size());
  std::vector<std::vector<float>> eval_targets;
  for (size_t i = 0; i < clips.size(); ++i) {
    const ClipInfo& c = clips[i];
    const fs::path file = c.dir / "tracks.json";
    if (!fs::exists(file))
      throw std::runtime_error(file.string() + " not found: --aux-tracks trains on a dataset made with "
                               "`clothwind make-dataset --tracks COLSxROWS` (or given them by --add-tracks)");
    aux.tracks[i] = ReadTracks(file);
    const Tracks& t = aux.tracks[i];
    if (t.frames != c.num_frames || t.width != c.width || t.height != c.height ||
        (i > 0 && t.points() != aux.tracks[0].points()))
      throw std::runtime_error(file.string() + ": " + std::to_string(t.frames) + " frames of " +
                               std::to_string(t.width) + "x" + std::to_string(t.height) + " px and " +
                               std::to_string(t.points()) + " points, expected the clip's " +
                               std::to_string(c.num_frames) + " frames of " + std::to_string(c.width) + "x" +
                               std::to_string(c.height) + (i > 0 ? " and the other clips' grid" : ""));
    if (world && t.world.empty())
      throw std::runtime_error(file.string() + ": field 'world' is missing: --aux-world needs the points' positions "
                               "(give the dataset them with `clothwind make-dataset --add-tracks --tracks COLSxROWS` "
                               "and the options it was made with)");
    const int first = (c.num_frames - options.frames) / 2;
    const cv::Rect whole = CentreSquare(c.width, c.height);
    try {
      for (bool flipped : {false, true})
        eval_targets.push_back(AuxTargetsOf(t, first, options.frames, whole, c.width, flipped, phase_bins, world));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(file.string() + ": " + e.what());
    }
  }
  aux.scale = ScaleOf(eval_targets);
  return aux;
}

}  // namespace clothwind::learn
