#ifndef CLOTHWIND_RENDER_FLAG_DESIGNS_H_
#define CLOTHWIND_RENDER_FLAG_DESIGNS_H_

#include <array>
#include <cstdint>
#include <string>

#include "render/color.h"
#include "render/texture.h"

namespace clothwind::render {

// Procedural flag layouts, standing in for the seed's "12 countries" (Table 2, mesh_texture):
// the estimator must not learn a particular flag, only how cloth moves, so what matters is a
// spread of layouts (bands both ways, crosses, cantons, emblems, diagonals) and colours.
enum class FlagDesign {
  kVerticalTricolour = 0,  // three bands along the length (France, Italy, Ireland)
  kHorizontalTricolour,    // three bands top to bottom (Germany, Netherlands)
  kHorizontalBicolour,     // two bands (Poland, Ukraine)
  kNordicCross,            // off-centre cross, optionally fimbriated (Denmark, Norway)
  kStripesWithCanton,      // alternating stripes, canton with a grid of stars (USA, Malaysia)
  kDiscOnField,            // disc near the centre (Japan, Bangladesh)
  kDiagonalBicolour,       // split along the diagonal
  kDiagonalBand,           // fimbriated band along the diagonal (Tanzania, Congo)
  kSaltire,                // X cross (Scotland, Jamaica)
  kCentredCross,           // symmetric cross (England, Switzerland-like)
  kHoistTriangle,          // two bands with a triangle at the hoist (Czechia, Philippines)
  kHoistBand,              // vertical band at the hoist, three bands beside it (UAE)
  kStarOnField,            // five-pointed star in the centre (Vietnam)
  kCrescentAndStar,        // crescent and star (Turkey, Tunisia-like)
  kFiveBands,              // five horizontal bands, symmetric, wider centre (Thailand)
  kQuartered,              // four quarters (Panama-like, plain)
  kCount
};

constexpr int kNumFlagDesigns = static_cast<int>(FlagDesign::kCount);

// Name of a design, e.g. "vertical_tricolour" (used in label.json).
std::string FlagDesignName(FlagDesign design);
// Inverse of FlagDesignName; throws std::invalid_argument naming the unknown value.
FlagDesign FlagDesignFromName(const std::string& name);

// The colours a design is drawn with (linear RGB), chosen from a palette of flag colours by
// seed: distinct entries, each jittered slightly in brightness and hue.
struct FlagColours {
  std::array<Rgb, 4> c;
};
// Inputs: seed  colour seed.
FlagColours SampleFlagColours(uint64_t seed);

// Colour of a design at texture coordinates (u along the length from the hoist, v bottom to
// top, both in [0,1]) for a flag of aspect length:height = aspect. Exact (not anti-aliased).
Rgb FlagColourAt(FlagDesign design, const FlagColours& colours, float u, float v,
                 float aspect = 1.5f);

// Rasterises a design into a texture with 3x3 supersampling per texel (smooth edges).
// Inputs: design; colours; width, height  texture size in texels (width/height is the aspect).
Texture DrawFlag(FlagDesign design, const FlagColours& colours, int width = 300,
                 int height = 200);

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_FLAG_DESIGNS_H_
