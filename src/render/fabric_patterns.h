#ifndef CLOTHWIND_RENDER_FABRIC_PATTERNS_H_
#define CLOTHWIND_RENDER_FABRIC_PATTERNS_H_

#include <cstdint>
#include <string>

#include "render/texture.h"

namespace clothwind::render {

// Procedural fabric prints for the hanging cloth (ClothSim; Table 2 samples them from the
// fabrics of Yang et al.): what matters to the estimator is that folds are visible through
// the print at several scales.
enum class FabricPattern {
  kPlain = 0,  // one colour with a faint weave
  kStripes,    // two or three colours, straight or diagonal
  kChecks,     // gingham: two crossing stripe sets blend
  kDots,       // polka dots on a staggered grid
  kKnit,       // rib knit with heathered (noisy) yarn
  kCount
};
constexpr int kNumFabricPatterns = static_cast<int>(FabricPattern::kCount);

// Name of a pattern, e.g. "checks" (used in label.json); and its inverse (throws on unknown).
std::string FabricPatternName(FabricPattern pattern);
FabricPattern FabricPatternFromName(const std::string& name);

// Draws a pattern whose colours, scale and orientation come from the seed.
// Inputs: pattern; seed; size  the texture is size by size texels, spanning the whole cloth
//   (UV [0,1]^2).
Texture DrawFabric(FabricPattern pattern, uint64_t seed, int size = 256);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_FABRIC_PATTERNS_H_
