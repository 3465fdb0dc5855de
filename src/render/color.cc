#include "render/color.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace clothwind::render {

float SrgbToLinear(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

float LinearToSrgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

Rgb FromSrgb8(int r, int g, int b) {
  const float* t = SrgbToLinearTable();
  return Rgb(t[std::clamp(r, 0, 255)], t[std::clamp(g, 0, 255)], t[std::clamp(b, 0, 255)]);
}

uint8_t ToSrgb8(float linear) {
  // A 4096-entry table over [0,1] keeps the per-pixel cost at one lookup; the error is far
  // below one 8-bit step except in the darkest few codes, where the slope is linear anyway.
  static const std::array<uint8_t, 4097> table = [] {
    std::array<uint8_t, 4097> t{};
    for (int i = 0; i <= 4096; ++i)
      t[i] = static_cast<uint8_t>(std::lround(255.0f * LinearToSrgb(i / 4096.0f)));
    return t;
  }();
  if (!(linear > 0.0f)) return 0;  // also catches NaN
  if (linear >= 1.0f) return 255;
  return table[static_cast<int>(linear * 4096.0f + 0.5f)];
}

float Tone(float radiance) {
  return radiance > 0.0f ? 1.0f - std::exp(-kToneGain * radiance) : 0.0f;
}

float InverseTone(float display_linear) {
  const float y = std::clamp(display_linear, 0.0f, 0.998f);
  return -std::log1p(-y) / kToneGain;
}

const float* SrgbToLinearTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = SrgbToLinear(i / 255.0f);
    return t;
  }();
  return table.data();
}

}  // namespace clothwind::render
