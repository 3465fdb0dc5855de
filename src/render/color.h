#ifndef CLOTHWIND_RENDER_COLOR_H_
#define CLOTHWIND_RENDER_COLOR_H_

#include <Eigen/Core>
#include <cstdint>

namespace clothwind::render {

// Linear RGB radiance or reflectance (not gamma encoded). Shading happens in linear RGB;
// only the final frame is encoded to sRGB.
using Rgb = Eigen::Vector3f;

// sRGB transfer function (IEC 61966-2-1) and its inverse, per channel, in [0, 1].
float SrgbToLinear(float c);
float LinearToSrgb(float c);

// Colour from 8-bit sRGB components, returned linear.
Rgb FromSrgb8(int r, int g, int b);

// Linear colour to 8-bit sRGB (clamped).
uint8_t ToSrgb8(float linear);

// The film response between scene radiance and display value: y = 1 - exp(-kToneGain * L).
// Like Blender's Filmic it is near linear in the shadows and rolls highlights off instead of
// clipping them (a white flag in full sun stays textured). InverseTone maps a display value
// back to the radiance that reproduces it, so a photograph used as a backdrop comes out as
// itself.
constexpr float kToneGain = 1.6f;
float Tone(float radiance);
float InverseTone(float display_linear);

// Table lookup of SrgbToLinear for 8-bit inputs (fast path for photographs).
const float* SrgbToLinearTable();

}  // namespace clothwind::render

#endif  // CLOTHWIND_RENDER_COLOR_H_
